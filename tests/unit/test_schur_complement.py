"""Unit tests of the prototype's static condensation onto the contact DOFs
(python_prototype/contact/schur_complement.py) on a small full SPD matrix
built here, the twins of tests/unit/test_schur_complement.cpp:
H = A_CC - A_CI A_II^{-1} A_IC and g = b_C - A_CI A_II^{-1} b_I as the dense
formulas give them, H symmetric positive definite, the condensed problem
solved by the full one's x_C, the extension solving the equations of I, and H
formed anew from A's current values."""
import os
import sys
import unittest

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
import support  # noqa: E402,F401  (the repository on sys.path)
from mpi4py import MPI  # noqa: E402
from python_prototype.contact.schur_complement import SchurComplement  # noqa: E402
from python_prototype.solvers.solver import Method, Structure, set_solver_defaults  # noqa: E402
from dense import petsc_matrix, petsc_vector, spd_matrix  # noqa: E402

N = 10
CONTACT, INTERIOR = [1, 4, 6, 9], [0, 2, 3, 5, 7, 8]
B = np.array([1, -2, 0.5, 3, -1, 0.25, 2, -4, 1.5, -0.75])


class Schur(unittest.TestCase):
    def setUp(self):
        set_solver_defaults("schur_test_", Structure.spd, (Method.direct, "unit test"), MPI.COMM_WORLD)
        self.A = spd_matrix(N)
        self.petsc_A = petsc_matrix(self.A)
        self.schur = SchurComplement(MPI.COMM_WORLD, "schur_test_", self.petsc_A, Structure.spd, CONTACT)
        self.schur.assemble()
        self.round_off = 1e-14 * np.abs(self.A).max()

    def block(self, rows, columns):
        return self.A[np.ix_(rows, columns)]

    def test_matches_the_dense_formula(self):
        self.assertEqual(self.schur.size(), 4)
        self.assertEqual(self.schur.offset, 0)
        self.assertEqual(self.schur.columns, 4, "one right-hand side per contact DOF")
        expected = self.block(CONTACT, CONTACT) - self.block(CONTACT, INTERIOR) @ np.linalg.solve(
            self.block(INTERIOR, INTERIOR), self.block(INTERIOR, CONTACT))
        np.testing.assert_allclose(self.schur.H.getDenseArray(), expected, rtol=0, atol=self.round_off)

    def test_is_symmetric_positive_definite(self):
        # The Schur complement of an SPD matrix is SPD: Cholesky's pivots > 0.
        H = self.schur.H.getDenseArray().copy()
        np.testing.assert_allclose(H, H.T, rtol=0, atol=self.round_off)
        for k in range(H.shape[0]):
            self.assertGreater(H[k, k], 0, f"pivot {k}")
            H[k + 1:, k + 1:] -= np.outer(H[k + 1:, k], H[k, k + 1:]) / H[k, k]

    def test_condensed_load_matches_the_dense_formula(self):
        g = self.schur.condensed_load(petsc_vector(self.petsc_A, B))
        v = np.linalg.solve(self.block(INTERIOR, INTERIOR), B[INTERIOR])
        np.testing.assert_allclose(g, B[CONTACT] - self.block(CONTACT, INTERIOR) @ v, rtol=0, atol=self.round_off)

    def test_condensed_problem_has_the_same_solution(self):
        # x solves A x = b: y = x_C (restrict_to_contact) solves H y = g.
        x = np.linalg.solve(self.A, B)
        y = self.schur.restrict_to_contact(petsc_vector(self.petsc_A, x))
        np.testing.assert_array_equal(y, x[CONTACT])
        g = self.schur.condensed_load(petsc_vector(self.petsc_A, B))
        np.testing.assert_allclose(self.schur.H.getDenseArray() @ y - g, 0.0, rtol=0, atol=1e-14 * np.abs(B).max())

    def test_extension_solves_the_interior_equations(self):
        # x_C = y exactly, and the equations of I hold: (A x - b)_I = 0.
        y = np.array([1e-3, -2e-3, 0.5, 4])
        b = petsc_vector(self.petsc_A, B)
        x = b.duplicate()
        self.schur.extend(b, y, x)
        x = x.getArray(readonly=True)
        np.testing.assert_array_equal(x[CONTACT], y)
        np.testing.assert_allclose((self.A @ x - B)[INTERIOR], 0.0, rtol=0, atol=self.round_off * np.abs(x).max())

    def test_reassembly_follows_the_values(self):
        # assemble() forms H from A's current values: A doubled, H doubles.
        before = self.schur.H.getDenseArray().copy()
        self.petsc_A.scale(2.0)
        self.schur.assemble()
        self.assertEqual(self.schur.columns, 8, "4 right-hand sides per formation")
        np.testing.assert_allclose(self.schur.H.getDenseArray(), 2 * before, rtol=0, atol=2 * self.round_off)


if __name__ == "__main__":
    unittest.main()
