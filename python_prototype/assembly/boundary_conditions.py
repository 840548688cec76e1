"""Essential boundary conditions: the displacement values and the normal
flux (prescribed on flux and rate boundaries, zero elsewhere where no
pressure is given) (cpp/assembly/boundary_conditions.cpp)."""

import numpy as np
from dolfinx import fem, mesh as dmesh

from ..domain.domain import planar_boundary
from ..scene.input import FaultFlow


def displacement_bcs(scene, domain, U):
    """One DirichletBC per prescribed displacement component; returns the
    conditions and (expression, value Function) pairs to update in time."""
    bcs, values = [], []
    d = domain.dim
    for name, b in scene.boundaries.items():
        for i in range(d):
            if b.displacement[i] is None:
                continue
            Ui = U.sub(i)
            collapsed, _ = Ui.collapse()
            g = fem.Function(collapsed)
            dofs = fem.locate_dofs_topological((Ui, collapsed), d - 1, domain.boundaries[name])
            bcs.append(fem.dirichletbc(g, dofs, Ui))
            points = collapsed.tabulate_dof_coordinates()[dofs[1]]
            values.append((b.displacement[i], g, dofs[1], points))
    return bcs, values


def update(values, t):
    """The prescribed values at time t, evaluated at the boundary DOFs only
    (a closed form such as Mandel's plate displacement costs a series per point)."""
    for expression, g, dofs, points in values:
        g.x.array[dofs] = expression.at(points.T, t)


class FluxBoundary:
    """The prescribed normal flux z.n = g of one (planar) flux or rate
    boundary: g = flux(x, t), or g = -rate(t) / measure spread uniformly."""

    def __init__(self, b, plane, cells, dofs):
        self.flux, self.rate = (None, b.rate) if b.rate is not None else (b.flux, None)
        self.plane, self.cells, self.dofs = plane, cells, dofs


class FluxValues:
    """The values of the essential flux condition: zero on no-flow facets,
    set by update_fluxes on the flux and rate boundaries."""

    def __init__(self, g):
        self.g, self.boundaries = g, []


def flux_bc(scene, domain, Z):
    """z.n = g on every boundary facet that is not a pressure boundary nor a
    face of a fault held at its pressure (g = 0 but on flux and rate
    boundaries); returns the condition and its FluxValues."""
    d = domain.dim
    facets = dmesh.exterior_facet_indices(domain.mesh.topology)
    for name, b in scene.boundaries.items():
        if b.flow == "pressure":
            facets = np.setdiff1d(facets, domain.boundaries[name])
    # A fault's faces are exterior facets of the split mesh: no flow crosses
    # them ("sealing") unless they are pressure boundaries.
    for name, f in scene.faults.items():
        if f.flow == FaultFlow.pressure:
            fault = domain.faults[name]
            facets = np.setdiff1d(facets, np.concatenate([fault.plus_facets, fault.minus_facets]))
    collapsed, _ = Z.collapse()
    values = FluxValues(fem.Function(collapsed))
    f_to_c = domain.mesh.topology.connectivity(d - 1, d)
    for name, b in sorted(scene.boundaries.items()):  # the order of the C++ std::map
        if b.flow == "flux":
            boundary = domain.boundaries[name]
            cells = np.array([f_to_c.links(f)[0] for f in boundary], dtype=np.int32)
            values.boundaries.append(FluxBoundary(b, planar_boundary(domain, name, f"boundary.{name}"), cells,
                                                  fem.locate_dofs_topological(collapsed, d - 1, boundary)))
    dofs = fem.locate_dofs_topological((Z, collapsed), d - 1, facets)
    return fem.dirichletbc(values.g, dofs, Z), values


def update_fluxes(values, t):
    """g on the flux and rate boundaries at time t: the RT interpolation of
    g n on each boundary's cells, kept on its own facets only (a cell may
    touch two boundaries)."""
    if not values.boundaries:
        return
    boundary_g = fem.Function(values.g.function_space)
    gdim = values.g.function_space.mesh.geometry.dim
    for b in values.boundaries:
        def g_n(x, b=b):
            g = np.full(x.shape[1], -float(b.rate(0, 0, 0, t)) / b.plane.measure) if b.rate is not None \
                else b.flux.at(x, t)
            return np.outer(b.plane.normal[:gdim], g)
        boundary_g.interpolate(g_n, b.cells)
        values.g.x.array[b.dofs] = boundary_g.x.array[b.dofs]


