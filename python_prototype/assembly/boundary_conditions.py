"""Essential boundary conditions: the displacement values and the no-flow
flux condition (cpp/assembly/boundary_conditions.cpp)."""

import numpy as np
from dolfinx import fem, mesh as dmesh



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


def no_flow_bc(scene, domain, Z):
    """w.n = 0 on every boundary facet that is not a pressure boundary."""
    facets = dmesh.exterior_facet_indices(domain.mesh.topology)
    for name, b in scene.boundaries.items():
        if b.flow == "pressure":
            facets = np.setdiff1d(facets, domain.boundaries[name])
    collapsed, _ = Z.collapse()
    dofs = fem.locate_dofs_topological((Z, collapsed), domain.dim - 1, facets)
    return fem.dirichletbc(fem.Function(collapsed), dofs, Z)


