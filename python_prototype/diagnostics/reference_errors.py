"""The errors of a run against its scene's closed form ([reference]:
Terzaghi or Mandel, closed_form.py) at the final time, for summary.json
(cpp/diagnostics/reference_errors.h)."""
from dataclasses import dataclass
from typing import Optional

import numpy as np
from dolfinx import fem

from ..scene.input import ReferenceSolution
from .closed_form import Mandel, Medium, Terzaghi
from .diagnostics import relative_error


@dataclass
class ReferenceErrors:
    """Relative L2 errors of pressure and displacement at `time`, and for
    Terzaghi the settlement of the top against the exact one."""

    @dataclass
    class Settlement:
        computed: float
        exact: float
        relative: float

    time: float = 0.0
    pressure_rel_l2: float = 0.0
    displacement_rel_l2: float = 0.0
    settlement: Optional[Settlement] = None


def _boundary_mean(u, facets, component, comm):
    """Mean of one displacement component over the nodes of a boundary (collective)."""
    V = u.function_space
    dofs = fem.locate_dofs_topological(V.sub(component), V.mesh.topology.dim - 1, facets)
    dofs = dofs[dofs < V.dofmap.index_map.size_local * V.dofmap.index_map_bs]
    total, count = comm.allreduce(np.array([u.x.array[dofs].sum(), len(dofs)]))
    return total / count


def reference_errors(problem, u, p):
    """The errors of (u, p) at the scene's end time against problem.scene's
    reference (which it must have); the closed form is interpolated into P2."""
    scene, parameters, F, comm = problem.scene, problem.parameters, problem.forms, problem.domain.mesh.comm
    ref, fs = scene.reference, scene.flow
    mobility = fs.permeability(0, 0, 0, 0) / fs.mu_f
    t, y0 = scene.end_time, scene.mesh.lower[1]
    # The closed form: pressure and displacement at the points x.
    terzaghi = None
    if ref.solution == ReferenceSolution.terzaghi:
        terzaghi = Terzaghi(ref.height, parameters.G, parameters.lmbda, parameters.alpha, parameters.storage, mobility,
                            ref.load)
        p_exact = lambda x: terzaghi.pressure(x[1] - y0, t)  # noqa: E731
        u_exact = lambda x: [0.0 * x[0], terzaghi.displacement(x[1] - y0, t)]  # noqa: E731
    else:
        medium = Medium(parameters.G, parameters.lmbda, parameters.alpha, parameters.storage, mobility)
        mandel = Mandel(scene.mesh.upper[0], scene.mesh.upper[1], medium, ref.force)
        p_exact = lambda x: mandel.pressure(x[0], t)  # noqa: E731
        u_exact = lambda x: [mandel.displacement_x(x[0], t), mandel.displacement_y(x[1], t)]  # noqa: E731
    F["p_reference"].interpolate(p_exact)
    F["u_reference"].interpolate(lambda x: np.vstack(u_exact(x)))
    F["p_out"].x.array[:] = p.x.array
    F["u_out"].x.array[:] = u.x.array
    errors = ReferenceErrors(
        t, relative_error(F, F.compile("M_pressure_error"), F.compile("M_pressure_reference"), comm),
        relative_error(F, F.compile("M_displacement_error"), F.compile("M_displacement_reference"), comm))
    if terzaghi:
        settlement = -_boundary_mean(u, problem.domain.boundaries["top"], 1, comm)
        exact = terzaghi.settlement(t)
        errors.settlement = ReferenceErrors.Settlement(settlement, exact, abs(settlement - exact) / abs(exact))
    return errors
