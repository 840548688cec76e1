"""Unit tests of the 2 x 2 block matrix as one AIJ matrix
(python_prototype/solvers/block_matrix.py), the twins of
tests/unit/test_block_matrix.cpp: the conversion of [[A, E], [B, C]] is the
nest's, a refill sets every block anew, and a block None keeps its entries
(the appended operator's A between reassemblies)."""
import os
import sys
import unittest

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
import support  # noqa: E402,F401  (the repository on sys.path)
from petsc4py import PETSc  # noqa: E402
from python_prototype.solvers.block_matrix import BlockMatrix  # noqa: E402

N_A, N_C = 4, 2


def aij(values):
    """`values` as an AIJ matrix on one rank, zero entries left out but on
    the diagonal of a square one."""
    rows, columns = values.shape
    M = PETSc.Mat().createAIJ([rows, columns], nnz=columns, comm=PETSc.COMM_WORLD)
    M.setUp()
    for i in range(rows):
        for j in range(columns):
            if values[i, j] != 0 or (i == j and rows == columns):
                M.setValue(i, j, values[i, j])
    M.assemble()
    return M


def blocks(s):
    """The blocks [A, E, B, C] of one structure, their entries scaled by s,
    as dense arrays."""
    def entries(rows, columns, value):
        return np.fromfunction(np.vectorize(value), (rows, columns))
    return [entries(N_A, N_A, lambda i, j: s * (4.0 if i == j else -1.0 if i + j == 3 else 0.0)),
            entries(N_A, N_C, lambda i, j: s * 2.0 if i == 3 - j else 0.0),
            entries(N_C, N_A, lambda i, j: s * 3.0 if j == 3 - i else 0.0),
            entries(N_C, N_C, lambda i, j: s * -5.0 if i == j else 0.0)]


def whole_of(b):
    """[[A, E], [B, C]] (one rank: A's rows, then C's)."""
    return np.block([[b[0], b[1]], [b[2], b[3]]])


class BlockMatrixTest(unittest.TestCase):
    def test_refill_sets_every_block_and_a_null_block_keeps_its_entries(self):
        first, second, third = blocks(1.0), blocks(2.0), blocks(3.0)
        m_first, m_second, m_third = ([aij(v) for v in b] for b in (first, second, third))
        layout = BlockMatrix(m_first[0], m_first[3])
        whole = layout.convert(PETSc.COMM_WORLD, m_first)
        np.testing.assert_array_equal(whole.getValues(range(6), range(6)), whole_of(first))
        layout.refill(whole, m_second)
        np.testing.assert_array_equal(whole.getValues(range(6), range(6)), whole_of(second))
        # A kept: its block is the second's, E, B and C the third's
        layout.refill(whole, [None] + m_third[1:])
        np.testing.assert_array_equal(whole.getValues(range(6), range(6)), whole_of([second[0]] + third[1:]))


if __name__ == "__main__":
    unittest.main()
