"""Unknowns tied in pairs, x_j = s x_i, eliminated from A x = b
(cpp/assembly/tied_dofs.h): x = P y with P = I + sum_k s_k e_{j_k} e_{i_k}^T,
A' = P^T A P with the rows and columns j made identity rows, b' = P^T b
with b'_j = 0 (the null-space method of the linear constraints). The
constraint's multiplier is -(A x - b)_j."""
from dataclasses import dataclass

from mpi4py import MPI
from petsc4py import PETSc


@dataclass
class Tie:
    """One tie x_j = s x_i by global indices (i and j may be owned by two ranks)."""
    i: int
    j: int
    s: float


class TiedDofs:
    """The elimination of tied unknowns from systems like A; P from the ties
    whose j this rank owns (collective)."""

    def __init__(self, A, ties):
        (m, n), start, end = A.getLocalSize(), *A.getOwnershipRange()
        self.P = PETSc.Mat().createAIJ(((m, None), (n, None)), nnz=(2, 1), comm=A.getComm())
        for r in range(start, end):  # row j of P holds 1 at j and s at i (i possibly off this rank)
            self.P.setValue(r, r, 1.0)
        for t in ties:
            self.P.setValue(t.j, t.i, t.s)
        self.P.assemble()
        self.j = [t.j for t in ties]
        self.size = A.getComm().tompi4py().allreduce(len(self.j), op=MPI.SUM)

    def reduce(self, A, At=None):
        """A' = P^T A P, rows and columns j identity (collective); reuses At's
        structure when given."""
        At = A.PtAP(self.P, result=At)
        At.zeroRowsColumns(self.j, diag=1.0)
        return At

    def load(self, b, bt):
        """b' = P^T b, b'_j = 0."""
        self.P.multTranspose(b, bt)
        self._zero(bt)

    def guess(self, x, y):
        """y from an x that satisfies the ties: x with y_j = 0 (a solve's guess)."""
        x.copy(y)
        self._zero(y)

    def expand(self, y, x):
        """x = P y."""
        self.P.mult(y, x)

    def _zero(self, v):
        v.setValues(self.j, [0.0] * len(self.j))
        v.assemble()
