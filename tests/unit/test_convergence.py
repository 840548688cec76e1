"""Unit tests of the prototype's stopping rules of the contact solve
(python_prototype/contact/convergence.py), the twins of
tests/unit/test_convergence.cpp: the round-off bound of a residual
W (K y - b) is eps (W |K| |y| + |b|) row by row, whatever the signs of K, y
and b; a solve's residual norms cycle when they alternate between two
values; and a frictional solve whose forces are solved and whose separate
rows jitter within their round-off, above atol, ends solved."""
import os
import sys
import unittest

import numpy as np
from mpi4py import MPI
from petsc4py import PETSc

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
import support  # noqa: E402,F401  (the repository on sys.path)
from python_prototype.contact.convergence import (STALL_REDUCTION, ContactConvergence, VIBounds,  # noqa: E402
                                                  newton_cycle, newton_stall, rejoins_attempt, residual_round_off)
from dense import petsc_matrix, petsc_vector, spd_matrix  # noqa: E402


def signed_matrix():
    """spd_matrix(5) with the signs of its off-diagonal entries alternating."""
    i = np.arange(5)
    return spd_matrix(5) * np.where((i[:, None] + i[None, :]) % 2 == 1, -1.0, 1.0)


class ConvergenceTests(unittest.TestCase):
    def test_round_off_is_eps_times_the_magnitudes(self):
        A = signed_matrix()
        y, b, w = (np.array(v) for v in ([1.0, -2.0, 3.0, -4.0, 5.0], [-1e3, 0.0, 2e3, -3e3, 0.0],
                                          [1.0, 2.0, 0.5, 1.0, 4.0]))
        K = petsc_matrix(A)
        Y, B, W, r = (petsc_vector(K, v) for v in (y, b, w, y))
        for weights in (None, W):
            residual_round_off(K, weights, Y, B, r)
            expected = np.finfo(float).eps * ((1.0 if weights is None else w) * (np.abs(A) @ np.abs(y)) + np.abs(b))
            np.testing.assert_allclose(r.array_r, expected, rtol=1e-14)
        np.testing.assert_array_equal(Y.array_r, y)  # y and b are left as they were
        np.testing.assert_array_equal(B.array_r, b)

    def test_newton_cycle_is_a_repeated_cycle_of_residuals(self):
        # Phan's crack loaded at once on the coupled system: 1.0123e7 and
        # 1.0125e7 in turn after two steps that differ
        norms = [1.8e9, 4.7e8] + [1.0123e7 if k % 2 == 0 else 1.0125e7 for k in range(6)]
        self.assertTrue(newton_cycle(norms, 3))
        self.assertFalse(newton_cycle(norms[:7], 3))  # two periods and a half
        self.assertTrue(newton_cycle(norms[:6], 2))
        near = norms[:-1] + [norms[-1] * (1 + 1e-8)]  # the last differs in the 8th digit
        self.assertFalse(newton_cycle(near, 3))
        self.assertFalse(newton_cycle([1e7] * 8, 3))  # stagnation is not a cycle
        self.assertFalse(newton_cycle([8, 7, 6, 5, 4, 3, 2, 1], 3))
        self.assertFalse(newton_cycle([], 3))
        # its cohesive crack opening along its whole length: four states
        four = [4.1e7, 2.7e7] + [[2.9087e7, 2.6532e7, 2.6526e7, 2.9186e7][k % 4] for k in range(12)]
        self.assertTrue(newton_cycle(four, 3))
        self.assertFalse(newton_cycle(four[:12], 3))  # two periods and a half
        # network3d's monolithic step at 0.5 m^3/s: nine states
        nine = [5.4e10, 2.8e10] + [2.0e9 + 1e9 * (k % 9) for k in range(27)]
        self.assertTrue(newton_cycle(nine, 3))
        self.assertFalse(newton_cycle(nine[:27], 3))  # two periods and a half
        self.assertFalse(newton_cycle([1.0] + [2.0 + k % 13 for k in range(39)], 3))  # longer than LONGEST_NEWTON_CYCLE

    def test_a_clamped_start_rejoins_the_attempt_at_its_first_step(self):
        # test_cohesive_opening's onset on the coupled system: the first
        # attempt from the last solution, the clamped start from every pair
        # stuck, both landing on 2.745445253772e7 after one step
        attempt = [7.283e-4, 2.745445253772e7, 2.768804085196e7, 2.535540936328e7]
        clamped = [4.094618846568e7, 2.745445253772e7]
        self.assertTrue(rejoins_attempt(clamped, attempt))
        self.assertFalse(rejoins_attempt([clamped[0], clamped[1] * (1 + 1e-8)], attempt))  # another iterate
        self.assertFalse(rejoins_attempt(clamped[:1], attempt))  # no step yet
        self.assertFalse(rejoins_attempt(clamped + [attempt[2]], attempt))  # decided at the first step only
        self.assertFalse(rejoins_attempt(clamped, attempt[:1]))  # the attempt took no step
        self.assertFalse(rejoins_attempt(clamped, []))

    def test_newton_stall_is_every_step_below_its_fraction(self):
        # the 50-fracture network's initial equilibrium on 2 ranks
        # (bench/network.py at size 0.5): its line search shrank the first
        # steps to 1e-11 and 1e-7
        network = [2.995830435789e9, 2.995830435731e9, 2.995830249459e9, 2.995829726679e9, 2.994522346468e9]
        self.assertFalse(newton_stall(network[:3], 3))  # two steps
        self.assertTrue(newton_stall(network[:4], 3))
        self.assertTrue(newton_stall(network, 3))  # the 4th step: 4.4e-4
        # one step of 0.1 % among the last three is progress
        self.assertFalse(newton_stall(network + [network[-1] * (1 - 1.01 * STALL_REDUCTION)], 3))
        self.assertFalse(newton_stall([8, 7, 6, 5], 3))
        self.assertTrue(newton_stall([1, 2, 3, 4], 3))  # a step that raised it reduced it by less
        self.assertTrue(newton_stall([1e7] * 4, 3))
        self.assertFalse(newton_stall([], 3))
        self.assertFalse(newton_stall([1e7] * 4, 0))

    def test_the_force_tests_leave_out_the_separate_rows(self):
        # the forces solved at the first step, the separate row within its
        # round-off: solved, though SNES's norm (50) stays above atol
        # (network3d's monolithic step, 100 Newton steps at 55-70 N against
        # atol 53)
        self.assertEqual(jittery_solve(), PETSc.SNES.ConvergedReason.CONVERGED_FNORM_ABS)


def jittery_solve():
    """The reason a frictional solve of F(x) = x - b (J = I, no bounds)
    ends with, whose separate row (the last) keeps a residual of +-50 that
    no step removes (a mass balance at its round-off), the round-off
    measured on diag(1, 1, 1e18): the separate row's is eps 1e18 |y_2| = 22
    at y_2 = 1, above its jitter, which lies above atol (1e-12 of the
    load, 0.14) and the relative target (rtol 1e-10 of the first residual,
    14)."""
    J, K = petsc_matrix(np.eye(3)), petsc_matrix(np.diag([1.0, 1.0, 1e18]))
    b, x = petsc_vector(J, [1e11, 1e11, 1.0]), petsc_vector(J, [0.0, 0.0, 0.0])
    lower, upper = petsc_vector(J, [PETSc.NINFINITY] * 3), petsc_vector(J, [PETSc.INFINITY] * 3)
    calls = [0]

    def residual(snes, X, F):
        X.copy(F)
        F.axpy(-1.0, b)
        F.setValue(2, (50.0 if calls[0] % 2 == 0 else -50.0), addv=PETSc.InsertMode.ADD_VALUES)
        F.assemble()
        calls[0] += 1

    snes = PETSc.SNES().create(PETSc.COMM_WORLD)
    snes.setType("vinewtonrsls")
    snes.setFunction(residual, J.createVecLeft())
    snes.setJacobian(lambda *args: None, J, J)
    snes.setVariableBounds(lower, upper)
    snes.setTolerances(atol=1e-12 * np.sqrt(2.0) * 1e11, rtol=1e-10, stol=1e-12, max_it=20)
    snes.setOptionsPrefix("unit_jittery_")
    PETSc.Options().setValue("unit_jittery_snes_linesearch_type", "basic")
    snes.setFromOptions()
    snes.getKSP().setType("preonly")
    convergence = ContactConvergence(MPI.COMM_WORLD, VIBounds(lower, upper, np.array([], dtype=np.int32)), [2])
    convergence.attach(snes, b, True)
    convergence.measure_round_off(K, None)
    convergence.pose()
    snes.solve(None, x)
    reason = snes.getConvergedReason()
    snes.destroy()
    return reason


if __name__ == "__main__":
    unittest.main()
