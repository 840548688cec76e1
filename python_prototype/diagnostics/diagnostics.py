"""What a run measures of its fields: the contraction norm, the volumetric
stress, relative errors (cpp/diagnostics/diagnostics.cpp)."""

import numpy as np
from dolfinx import fem
from mpi4py import MPI

from ..assembly.linear_algebra import accumulate_ghosts, add_vector, assemble_operator


class ContractionNorm:
    """||c_u div(du) - c_p dp||_L2 (cpp/diagnostics/diagnostics.h): with D the operator of
    the cell integrals of div and |T| the cell volumes, for P1 du and P0 dp
    exactly sum_T (c_u (D du)_T - c_p |T| dp_T)^2 / |T|."""

    def __init__(self, F, comm):
        self.comm = comm
        self.D = assemble_operator(F.compile("a_divergence"), [])
        self.volume = fem.Function(F["Q"])
        add_vector(self.volume, F.compile("L_cell_volume"))
        accumulate_ghosts(self.volume)
        self.du, self.div_du = fem.Function(F["V"]), fem.Function(F["Q"])
        self.cells = F["Q"].dofmap.index_map.size_local

    def __call__(self, c_u, du, c_p, dp):
        self.du.x.array[:] = du
        self.D.mult(self.du.vector, self.div_du.vector)
        n = self.cells
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
