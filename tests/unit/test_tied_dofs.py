"""Unit tests of the prototype's tied unknowns
(python_prototype/assembly/tied_dofs.py), the twins of
tests/unit/test_tied_dofs.cpp: the tied system A' = P^T A P (rows and
columns j identity) is symmetric, and its solution, expanded, satisfies the
ties x_j = s x_i and the optimality conditions of the constrained problem:
A x - b is zero at the free unknowns, and at a tie's pair (i, j) it is the
multiplier's, r_i = -s r_j. Reassembly reuses A''s structure."""
import os
import sys
import unittest

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
import support  # noqa: E402,F401  (the repository on sys.path)
from python_prototype.assembly.tied_dofs import Tie, TiedDofs  # noqa: E402
from dense import petsc_matrix, petsc_vector, spd_matrix  # noqa: E402

TIES = [Tie(1, 3, -2.0), Tie(0, 4, 0.5)]
LOAD = np.array([1.0, 2.0, 3.0, 4.0, 5.0])


def dense(M):
    """M's entries (a copy: petsc4py's convert() alone converts M itself)."""
    n = M.getSize()[0]
    return M.getValues(range(n), range(n))


class TiedDofsTests(unittest.TestCase):
    def test_tied_system_is_symmetric_with_identity_rows(self):
        A = petsc_matrix(spd_matrix(5))
        tied = TiedDofs(A, TIES)
        self.assertEqual(tied.size, 2)
        D = dense(tied.reduce(A))
        np.testing.assert_allclose(D, D.T, rtol=0, atol=1e-14)
        np.testing.assert_array_equal(D[3:, :], np.eye(5)[3:, :])
        np.testing.assert_array_equal(D[:, 3:], np.eye(5)[:, 3:])

    def test_solution_satisfies_ties_and_optimality(self):
        dA = spd_matrix(5)
        A = petsc_matrix(dA)
        tied = TiedDofs(A, TIES)
        At = tied.reduce(A)
        b, bt, x = petsc_vector(A, LOAD), petsc_vector(A, LOAD), petsc_vector(A, LOAD)
        tied.load(b, bt)
        y = petsc_vector(A, np.linalg.solve(dense(At), bt.getArray()))
        tied.expand(y, x)
        x = x.getArray()
        self.assertEqual(x[3], -2.0 * x[1])
        self.assertEqual(x[4], 0.5 * x[0])
        r = dA @ x - LOAD
        scale = np.abs(LOAD).max()
        self.assertLess(abs(r[2]), 1e-14 * scale, "a free unknown's equation holds")
        self.assertGreater(abs(r[3]), 1e-3 * scale, "the tie carries a force")
        for t in TIES:
            self.assertAlmostEqual(r[t.i], -t.s * r[t.j], delta=1e-14 * scale, msg=f"tie {t.i} - {t.j}")

    def test_reassembly_reuses_the_structure(self):
        A = petsc_matrix(spd_matrix(5))
        tied = TiedDofs(A, TIES)
        At = tied.reduce(A)
        once = dense(At)
        A.scale(3.0)
        again = tied.reduce(A, At)
        self.assertIs(again, At)
        expected = 3 * once
        expected[3:, :], expected[:, 3:] = once[3:, :], once[:, 3:]
        np.testing.assert_allclose(dense(again), expected, rtol=0, atol=1e-13)


if __name__ == "__main__":
    unittest.main()
