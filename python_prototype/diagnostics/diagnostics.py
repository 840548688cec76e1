"""What a run measures of its fields: the contraction norm, the volumetric
stress, relative errors (cpp/diagnostics/diagnostics.cpp)."""

import numpy as np
from dolfinx import fem
from mpi4py import MPI

from ..assembly.linear_algebra import accumulate_ghosts, add_vector, assemble_operator


class ContractionNorm:
    """The norms ||c_u div(du) - c_p dp||_L2 of the coupling with cell-wise
    coefficients from the materials of the cells (cpp/diagnostics/diagnostics.h):
    "theorem1" (lambda w, alpha w; w = sqrt(lambda_max/lambda)), "theorem2"
    (alpha/(q L), 1; 0 where L = 0),
    "coupled_residual" (alpha/q, L) and "fluid_content" (alpha, -S). With D
    the operator of the cell integrals of div and |T| the cell volumes, for
    P1 du and P0 dp exactly sum_T (c_u,T (D du)_T - c_p,T |T| dp_T)^2 / |T|."""

    def __init__(self, F, q, comm):
        self.comm = comm
        lmbda, alpha, storage, L = (F[name].x.array.copy() for name in ("lmbda", "alpha", "storage", "L"))
        # Theorem 1 holds with the largest gamma in the norm weighted by
        # lambda_max/lambda (docs/theory.md, "Material regions"); the plain
        # norm where lambda is constant, and where some lambda <= 0.
        lambda_max = comm.allreduce(float(lmbda.max(initial=0.0)), op=MPI.MAX)
        lambda_min = comm.allreduce(float(lmbda.min(initial=np.inf)), op=MPI.MIN)
        with np.errstate(divide="ignore", invalid="ignore"):
            w = np.sqrt(lambda_max / lmbda) if lambda_min > 0 else np.ones_like(lmbda)
            self.alpha_L = np.where(L > 0, alpha / L, 0.0)
        self.alpha = alpha
        self.coefficients = {"theorem1": (lmbda * w, alpha * w), "theorem2": (None, np.ones_like(L)),
                             "coupled_residual": (None, L), "fluid_content": (alpha, -storage)}
        self.set_window_steps(q)
        self.D = assemble_operator(F.compile("a_divergence"), [])
        self.volume = fem.Function(F["Q"])
        add_vector(self.volume, F.compile("L_cell_volume"))
        accumulate_ghosts(self.volume)
        self.du, self.div_du = fem.Function(F["V"]), fem.Function(F["Q"])
        self.cells = F["Q"].dofmap.index_map.size_local

    def set_window_steps(self, q):
        """The coefficients of theorem2 and coupled_residual for windows of q
        fine steps (coupling.q = "auto" changes q between windows)."""
        self.coefficients["theorem2"] = (self.alpha_L / q, self.coefficients["theorem2"][1])
        self.coefficients["coupled_residual"] = (self.alpha / q, self.coefficients["coupled_residual"][1])

    def __call__(self, quantity, du, dp):
        """The norm of `quantity` with the increments du and dp; du None
        keeps the last one's D du."""
        if du is not None:
            self.du.x.array[:] = du
            self.D.mult(self.du.vector, self.div_du.vector)
        n = self.cells
        c_u, c_p = (c[:n] for c in self.coefficients[quantity])
        volume = self.volume.x.array[:n]
        w = c_u * self.div_du.x.array[:n] - c_p * volume * dp[:n]
        return np.sqrt(self.comm.allreduce(float(np.sum(w * w / volume)), op=MPI.SUM))


def volumetric_stress(F, L_sigma_v, u, p, sigma_v):
    """sigma_v = lambda div u - alpha p in each cell (L_sigma_v); sigma_v on F["Q"]."""
    F["u_out"].x.array[:] = u.x.array
    F["p_out"].x.array[:] = p.x.array if p is not None else 0.0
    sigma_v.x.array[:] = 0.0
    add_vector(sigma_v, L_sigma_v)
    accumulate_ghosts(sigma_v)
    sigma_v.x.scatter_forward()


def relative_error(F, error, norm, comm):
    """||f - reference|| / ||reference|| with compiled forms (P2 reference);
    NaN or inf, as in C++, when the reference is zero."""
    e = comm.allreduce(fem.assemble_scalar(error), op=MPI.SUM)
    n = comm.allreduce(fem.assemble_scalar(norm), op=MPI.SUM)
    with np.errstate(divide="ignore", invalid="ignore"):
        return float(np.sqrt(np.float64(e) / n))
