"""A 2 x 2 block matrix as one parallel AIJ matrix, as PETSc's conversion of
a nest numbers it, and its values set again from blocks of the same
structure without a new conversion (a system with appended unknowns,
steps/system.py, whose blocks change at every aperture iteration). Twin:
cpp/solvers/block_matrix.h."""
import numpy as np
from petsc4py import PETSc


class BlockMatrix:
    """The numbering of [[A, E], [B, C]] as one matrix: each rank's rows of
    A, then its rows of C (A and C square, distributed by rows)."""

    def __init__(self, A, C):
        """The layout of the diagonal blocks A and C."""
        self.a = np.asarray(A.getOwnershipRanges(), dtype=PETSc.IntType)
        self.c = np.asarray(C.getOwnershipRanges(), dtype=PETSc.IntType)

    def convert(self, comm, blocks):
        """A new AIJ matrix of `blocks` [A, E, B, C] (the conversion of their
        nest; collective)."""
        A, E, B, C = blocks
        return PETSc.Mat().createNest([[A, E], [B, C]], comm=comm).convert("aij")

    def refill(self, whole, blocks):
        """Sets `whole`'s entries (from convert) to those of `blocks`, of the
        same structure: each rank its own rows, so nothing travels
        (collective). A block None keeps its entries."""
        for b, block in enumerate(blocks):
            if block is None:
                continue
            first, end = block.getOwnershipRange()
            indptr, columns, values = block.getValuesCSR()
            rows = self._whole_index(b // 2, np.arange(first, end, dtype=PETSc.IntType))
            whole.setValuesIJV(indptr, self._whole_index(b % 2, columns), values,
                               addv=PETSc.InsertMode.INSERT_VALUES, rowmap=rows)
        whole.assemble()

    def _whole_index(self, part, index):
        """The whole matrix's indices of `index` in the numbering of A (part
        0) or C (part 1): rank q's rows of A come after the rows of A and C
        of the ranks before it, its rows of C after its rows of A."""
        ranges = self.a if part == 0 else self.c
        q = np.searchsorted(ranges, index, side="right") - 1
        return (index + self.c[q] if part == 0 else self.a[q + 1] + index).astype(PETSc.IntType)
