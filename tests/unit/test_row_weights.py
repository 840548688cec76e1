"""Unit tests of the prototype's balanced rows
(python_prototype/solvers/row_weights.py), the twins of
tests/unit/test_row_weights.cpp: the leaves of nested field splits are the
system's rows; the weights make every leaf's largest entry the matrix's
largest, one constant per leaf; and W K y = W b has the solution of
K y = b, with W J rebuilt when K or J changes."""
import os
import sys
import unittest

import numpy as np
from petsc4py import PETSc

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
import support  # noqa: E402,F401  (the repository on sys.path)
from python_prototype.solvers.field_split import Field, part_of  # noqa: E402
from python_prototype.solvers.row_weights import BalancedRows, leaf_rows, set_balancing_weights  # noqa: E402
from dense import petsc_matrix, petsc_vector, spd_matrix  # noqa: E402

COMM = PETSc.COMM_WORLD.tompi4py()


def coupled_fields():
    """A coupled system's fields on 7 rows: the displacement (0-2) and the
    flow (3-6), split into the flux (3, 4) and the pressure (5, 6)."""
    mechanics, flow = Field("mechanics", np.arange(3)), Field("flow", np.arange(3, 7))
    flow.fields = [part_of(flow, "flux", np.array([3, 4]), COMM), part_of(flow, "pressure", np.array([5, 6]), COMM)]
    return [mechanics, flow]


def unbalanced():
    """spd_matrix(7) with the flux rows times 1e-6 and the pressure rows
    times 1e-9 (a coupled system's rows in their own units)."""
    A = spd_matrix(7)
    A[3:5] *= 1e-6
    A[5:] *= 1e-9
    return A


def dense(M):
    n = M.getSize()[0]
    return M.getValues(range(n), range(n))


class RowWeightsTests(unittest.TestCase):
    def test_leaves_are_the_systems_rows(self):
        leaves = leaf_rows(coupled_fields(), COMM)
        self.assertEqual([list(rows) for rows in leaves], [[0, 1, 2], [3, 4], [5, 6]])

    def test_every_leafs_largest_entry_becomes_the_matrixs(self):
        A = unbalanced()
        M = petsc_matrix(A)
        w = petsc_vector(M, np.zeros(7))
        set_balancing_weights(M, leaf_rows(coupled_fields(), COMM), w)
        W = w.getArray(readonly=True)
        self.assertEqual(W[0], 1.0)  # the displacement's rows hold the largest entry
        self.assertEqual(W[3], W[4])
        self.assertEqual(W[5], W[6])
        for rows in ([0, 1, 2], [3, 4], [5, 6]):
            self.assertAlmostEqual(np.abs(W[rows, None] * A[rows]).max(), 8.0, delta=1e-14 * 8)

    def test_balanced_system_has_the_same_solution(self):
        A = unbalanced()
        K = petsc_matrix(A)
        load = np.array([1.0, 2.0, 3.0, 4e-6, 5e-6, 6e-9, 7e-9])
        b = petsc_vector(K, load)
        balanced = BalancedRows(K, coupled_fields(), COMM)
        balanced.pose(K, K, b)
        x = np.linalg.solve(A, load)
        y = np.linalg.solve(dense(balanced.jacobian), balanced.load.getArray(readonly=True))
        np.testing.assert_allclose(y, x, rtol=0, atol=1e-12 * np.abs(x).max())
        # K reassembled (twice its values): W K follows, the weights unchanged
        K.scale(2.0)
        balanced.operator_changed()
        balanced.pose(K, K, b)
        W = balanced.weights.getArray(readonly=True)
        np.testing.assert_allclose(dense(balanced.jacobian), 2.0 * W[:, None] * A, rtol=0, atol=1e-15 * 16)


if __name__ == "__main__":
    unittest.main()
