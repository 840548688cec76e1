"""Unit tests of the prototype's componentwise backward error
(python_prototype/solvers/backward_error.py), the twins of
tests/unit/test_backward_error.cpp: at the round-off for the exact solution;
an error in a row 1e20 below the other is seen as in any row (the closed
form delta / (2 + delta), where ||b - A x|| / ||b|| is 1e-23); a row of
zeros counts 0."""
import os
import sys
import unittest

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
import support  # noqa: E402,F401  (the repository on sys.path)
from python_prototype.solvers.backward_error import backward_error  # noqa: E402
from dense import petsc_matrix, petsc_vector, spd_matrix  # noqa: E402


def error_of(A, x, b):
    """The backward error of x for A x = b, and the residual it leaves."""
    M = petsc_matrix(A)
    X, B, R = petsc_vector(M, x), petsc_vector(M, b), petsc_vector(M, np.zeros(len(b)))
    return backward_error(M, X, B, R), R.getArray().copy()


class BackwardErrorTests(unittest.TestCase):
    def test_exact_solution_is_at_round_off(self):
        A, x = spd_matrix(4), np.array([1.0, -2.0, 3.0, 0.5])
        self.assertLessEqual(error_of(A, x, A @ x)[0], 4e-16)

    def test_sees_a_row_far_below_the_other(self):
        A, delta = np.diag([1.0, 1e-20]), 1e-3
        error, r = error_of(A, [1.0, 1.0 + delta], [1.0, 1e-20])
        self.assertAlmostEqual(error, delta / (2 + delta), delta=1e-12)
        self.assertEqual(r[0], 0.0)
        self.assertAlmostEqual(r[1], -1e-20 * delta, delta=1e-35)

    def test_a_row_of_zeros_counts_zero(self):
        self.assertEqual(error_of(np.diag([1.0, 0.0]), [1.0, 5.0], [1.0, 0.0])[0], 0.0)


if __name__ == "__main__":
    unittest.main()
