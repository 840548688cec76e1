"""Row weights that balance the equations of a coupled system for a Krylov
method (cpp/solvers/row_weights.h): its residual norm adds forces (N) to
volumes per second (m^3/s), and FGMRES minimises that sum, blind to a mass
balance whose residual lies orders below the forces' round-off
(docs/theory.md, "Balanced rows"). Each field's rows are weighted by one
constant, so a preconditioner that splits along the fields is unchanged."""
import numpy as np
from mpi4py import MPI
from petsc4py import PETSc

from .field_split import block_offset


def leaf_rows(fields, comm):
    """The global rows of each field that is not split further (the
    displacement, the flux, the pressure), owned by this rank."""
    leaves = []

    def visit(f, to_global):
        if not f.fields:
            leaves.append(to_global(np.asarray(f.dofs, dtype=PETSc.IntType)))
            return
        offset = block_offset(f, comm)
        dofs = np.asarray(f.dofs, dtype=PETSc.IntType)
        for part in f.fields:
            visit(part, lambda rows, dofs=dofs: to_global(dofs[rows - offset]))

    for f in fields:
        visit(f, lambda rows: rows)
    return leaves


def set_balancing_weights(A, leaves, weights):
    """weights[i] = m / m_f for each row i of the leaf f, m_f the largest
    entry of the leaf's rows of A (in magnitude), m the largest of all
    leaves'; rows of no leaf keep weight 1 (collective)."""
    start = A.getOwnershipRange()[0]
    indptr, _, values = A.getValuesCSR()  # this rank's rows (MatGetRowMaxAbs of the C++)
    row_max = np.zeros(len(indptr) - 1)
    filled = indptr[1:] > indptr[:-1]
    row_max[filled] = np.maximum.reduceat(np.abs(values), indptr[:-1][filled])
    largest = np.array([row_max[rows - start].max(initial=0.0) for rows in leaves])
    A.getComm().tompi4py().Allreduce(MPI.IN_PLACE, largest, op=MPI.MAX)
    m = largest.max()
    with weights as w:
        w[:] = 1.0
        for rows, m_f in zip(leaves, largest):
            w[rows - start] = m / m_f if m_f > 0 else 1.0


class BalancedRows:
    """The Newton steps of K y = b solved as W K y = W b: the weights W, W b
    and W J for the Jacobian J (K, or friction's). The same steps and active
    sets (W > 0 keeps every force's sign); the Krylov method and the
    convergence tests see balanced rows."""

    def __init__(self, K, fields, comm):
        self.leaves = leaf_rows(fields, comm)
        self.weights, self.load = K.createVecs()
        self.jacobian = K.duplicate(copy=True)
        self.stale = True

    def operator_changed(self):
        """K was reassembled: the next pose() takes the weights from it again."""
        self.stale = True

    def pose(self, K, J, b):
        """Before a solve: the weights from K if it changed, W J, and W b."""
        if self.stale:
            set_balancing_weights(K, self.leaves, self.weights)
            self.weigh_jacobian(J)
            self.stale = False
        self.load.pointwiseMult(b, self.weights)

    def weigh_jacobian(self, J):
        """W J after J changed within a solve (friction; it may have grown
        beyond K's pattern)."""
        J.copy(self.jacobian, structure=PETSc.Mat.Structure.DIFFERENT_NONZERO_PATTERN)
        self.jacobian.diagonalScale(L=self.weights)
