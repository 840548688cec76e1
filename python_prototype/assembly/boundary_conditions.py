"""Essential boundary conditions: the displacement values and the normal
flux (prescribed on flux and rate boundaries, zero elsewhere where no
pressure is given) (cpp/assembly/boundary_conditions.cpp)."""

import numpy as np
from dolfinx import fem, mesh as dmesh

from ..domain.domain import vertex_input_indices
from ..domain.mesh_checks import planar_boundary
from .linear_algebra import accumulate_ghosts, add_vector
from .node_coordinates import node_coordinates
from .tied_dofs import Tie
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
            points = node_coordinates(collapsed)[dofs[1]]
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
    face of a fault held at its pressure or transparent (g = 0 but on flux
    and rate boundaries); returns the condition and its FluxValues."""
    d = domain.dim
    facets = dmesh.exterior_facet_indices(domain.mesh.topology)
    for name, b in scene.boundaries.items():
        if b.flow == "pressure":
            facets = np.setdiff1d(facets, domain.boundaries[name])
    # A fault's faces are exterior facets of the split mesh: no flow crosses
    # them ("sealing") unless they are pressure boundaries or the flux is
    # tied across them ("transparent", fault_flux_ties).
    for name, f in scene.faults.items():
        if f.flow != FaultFlow.sealing:
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




def facet_flux(F, L_pressure, space):
    """The flux of each basis function of the mixed space F[space] out through
    the facets a marker tags, <w.n, 1> (owned entries complete): the step's
    boundary-pressure load `L_pressure` with p_D = -1."""
    def flux(marker):
        F["p_boundary"].x.array[:] = -1.0
        b = fem.Function(F[space])
        add_vector(b, F.compile(L_pressure, marker))
        accumulate_ghosts(b)
        return b.x.array.copy()
    return flux


def fault_face_rows(domain, Z, name, flux):
    """Per face of the fault `name` on this rank whose RT0 DOF it owns: its
    side (0: +, 1: -), its + face's vertices' input indices (sorted: the two
    faces of a facet share them, and they are the fault cell's key,
    domain/fault_cells.py), the DOF's global index and its facet flux
    c = <w.n, 1>."""
    mesh, d = domain.mesh, domain.dim
    mesh.topology.create_connectivity(d - 1, 0)
    fault = domain.faults[name]
    # each - face's nodes (sorted) to its + face's: by facet, as a - node may
    # face two + nodes where another fault ends on this one
    cells = fault.cells
    plus_face = {tuple(sorted(minus)): tuple(plus) for plus, minus in zip(cells.keys.tolist(), cells.twins.tolist())}
    inputs = vertex_input_indices(mesh)
    f_to_v, f_to_c = mesh.topology.connectivity(d - 1, 0), mesh.topology.connectivity(d - 1, d)
    c_to_f = mesh.topology.connectivity(d, d - 1)
    index_map, layout = Z.dofmap.index_map, Z.dofmap.dof_layout
    rows = []
    for side, facets in enumerate((fault.plus_facets, fault.minus_facets)):
        for facet in facets:
            cell = f_to_c.links(facet)[0]
            local = list(c_to_f.links(cell)).index(facet)
            dof = Z.dofmap.cell_dofs(cell)[layout.entity_dofs(d - 1, local)[0]]
            if dof >= index_map.size_local:
                continue
            key = tuple(sorted(int(inputs[v]) for v in f_to_v.links(facet)))
            if side == 1:
                key = plus_face[key]
            rows.append((side, key, index_map.local_range[0] + int(dof), float(flux[dof])))
    return rows


def fault_flux_ties(scene, domain, Z, flux):
    """The flux across each "transparent" fault (cpp/assembly/boundary_conditions.h):
    c+ z+ + c- z- = 0 for the RT0 DOFs z+- of the two faces of each facet
    (c their facet flux), tied as z- = -(c+/c-) z+, given on the rank that
    owns z- (collective). Z is the flux subspace of the mixed space."""
    rows = []
    for name, f in sorted(scene.faults.items()):  # the order of the C++ std::map
        if scene.flow and f.flow == FaultFlow.transparent:
            rows += fault_face_rows(domain, Z, name, flux(domain.fault_faces(name)))
    plus = {key: (dof, c) for rank in domain.mesh.comm.allgather(rows) for side, key, dof, c in rank if side == 0}
    return [Tie(plus[key][0], dof, -plus[key][1] / c) for side, key, dof, c in rows if side == 1]
