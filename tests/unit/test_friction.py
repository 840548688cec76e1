"""Unit tests of the prototype's friction as the VI's equations
(python_prototype/contact/friction.py and the return map of contact_law.py),
the twins of tests/unit/test_friction.cpp: the projection on the disc sticks
inside, slips onto the bound along theta outside, leaves a constraint with
bound 0 free, and its derivatives are the finite differences of the force;
the tangential rows of F are c ds / s where a constraint sticks; and the
generalised Jacobian of friction_jacobian is F's finite-difference
derivative, in 2D and 3D, on a dense SPD K with one constraint stuck, one
slipping and one open; and its rows' weights (jacobian_weights) change with
the states alone in 2D, with a slip's trial force in 3D."""
import os
import sys
import unittest

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
import support  # noqa: E402,F401  (the repository on sys.path)
from dense import petsc_matrix, spd_matrix  # noqa: E402
from petsc4py import PETSc  # noqa: E402
from python_prototype.contact.contact_law import ContactLaw, project_on_disc, slip_bound_slope  # noqa: E402
from python_prototype.contact.friction import (FrictionalConstraint, FrictionPoint,  # noqa: E402
                                               add_friction_forces, friction_jacobian, friction_term,
                                               jacobian_weights)


def constraints():
    """Three constraints on 9 unknowns (normal, two tangents each), Coulomb
    mu = 0.5 with cohesion 0.1, bound on the upper side (sign +1) at gap 1:
    x_N = 1 is closed."""
    return [FrictionalConstraint(3 * k, [3 * k + 1, 3 * k + 2], 1.0, 1.0, 0.5, ContactLaw(0.5, 0.1))
            for k in range(3)]


def residual(K, b, x, tangents):
    """F(x) = K x - b plus friction (scale 1, the step's start 0)."""
    R = K @ x - b
    F = R.copy()
    add_friction_forces(constraints(), FrictionPoint(x, R, np.zeros(len(x)), np.diag(K).copy(), 1.0, tangents), F)
    return F


def loaded_point(tangents):
    """Constraint 0 closed and stuck (a small tangential load), 1 closed and
    slipping (a large one), 2 open (x_N below its gap)."""
    K = spd_matrix(9)
    x = np.array([1.0, 1e-3, -2e-3, 1.0, 0.3, 0.2, 0.5, 0.1, 0.1])
    if tangents == 1:
        x[[2, 5, 8]] = 0.0
    b = K @ x
    b[0] += 4.0  # pressing: t_N = 4 / 0.5 = 8
    b[3] += 4.0
    b[4] -= 30.0  # constraint 1 loaded far past its bound
    return K, x, b


def weights_at(tangents, stuck, slipping):
    """jacobian_weights at loaded_point, with the tangential loads `stuck`
    on constraint 0 and `slipping` on constraint 1."""
    K, x, _ = loaded_point(tangents)
    R = np.zeros(9)
    R[[0, 3]], R[1], R[4] = -4.0, stuck, slipping  # R = K x - b
    return jacobian_weights(constraints(), FrictionPoint(x, R, np.zeros(9), np.diag(K).copy(), 1.0, tangents))


class FrictionTest(unittest.TestCase):
    def test_jacobian_weights_follow_the_states(self):
        # 2D: the weights (and so J) change with a constraint's state only
        w = weights_at(1, 0.0, 30.0)
        self.assertEqual(len(w), 15)
        self.assertEqual(weights_at(1, 0.5, 40.0), w, "stuck and slipping as before: the same J")
        self.assertNotEqual(weights_at(1, 30.0, 30.0), w, "constraint 0 slips")
        self.assertNotEqual(weights_at(1, 0.0, -30.0), w, "constraint 1 slips the other way")
        # 3D: a slipping constraint's D turns with its trial force
        self.assertNotEqual(weights_at(2, 0.0, 40.0), weights_at(2, 0.0, 30.0))
        self.assertEqual(weights_at(2, 0.5, 30.0), weights_at(2, 0.0, 30.0), "stuck: D = I whatever the load")

    def test_disc_inside_sticks(self):
        p = project_on_disc(2.0, [1.0, -0.5], 2)
        self.assertTrue(p.stick)
        self.assertEqual(p.force, [1.0, -0.5])
        self.assertEqual(p.d_trial, [1.0, 0.0, 0.0, 1.0])
        self.assertEqual(p.d_bound, [0.0, 0.0])

    def test_disc_outside_slips_onto_the_bound(self):
        p = project_on_disc(2.0, [3.0, 4.0], 2)
        self.assertFalse(p.stick)
        self.assertAlmostEqual(p.force[0], 1.2, places=14)
        self.assertAlmostEqual(p.force[1], 1.6, places=14)
        self.assertAlmostEqual(p.d_bound[0], 0.6, places=14)
        # in 2D a slipping constraint's force is bound sign(theta): no d_trial
        q = project_on_disc(2.0, [-3.0, 0.0], 1)
        self.assertEqual(q.force[0], -2.0)
        self.assertEqual(q.d_trial[0], 0.0)
        self.assertEqual(q.d_bound[0], -1.0)

    def test_bound_zero_leaves_free(self):
        for trial in ([0.0, 0.0], [1.0, 2.0]):
            p = project_on_disc(0.0, trial, 2)
            self.assertFalse(p.stick)
            self.assertEqual(p.force, [0.0, 0.0])
            self.assertEqual(p.d_trial, [0.0] * 4)

    def test_disc_derivatives_are_finite_differences(self):
        trial, bound, h = [3.0, -4.0], 2.0, 1e-7
        p = project_on_disc(bound, trial, 2)
        for q in range(2):
            moved = list(trial)
            moved[q] += h
            m = project_on_disc(bound, moved, 2)
            for r in range(2):
                self.assertAlmostEqual(p.d_trial[2 * r + q], (m.force[r] - p.force[r]) / h, delta=1e-6)
        b = project_on_disc(bound + h, trial, 2)
        for r in range(2):
            self.assertAlmostEqual(p.d_bound[r], (b.force[r] - p.force[r]) / h, delta=1e-6)

    def test_slope_is_friction_where_pressed(self):
        self.assertEqual(slip_bound_slope(ContactLaw(0.6, 1e6), 1e6), 0.6)
        self.assertEqual(slip_bound_slope(ContactLaw(0.6, 1e6), -1e6), 0.0)
        self.assertEqual(slip_bound_slope(ContactLaw(0.6, 1e6, 2e6), 1e6), 0.0)

    def test_stuck_row_is_the_slip_increment(self):
        K = spd_matrix(9)
        x = np.array([1.0, 1e-3, -2e-3, 1.0, 0.0, 0.0, 0.5, 0.0, 0.0])
        b = K @ x
        b[0] += 4.0
        b[1] -= 0.1
        F = residual(K, b, x, 2)
        c = (K[1, 1] + K[2, 2]) / 2
        self.assertAlmostEqual(F[1], c * 1e-3, delta=1e-12)
        self.assertAlmostEqual(F[2], c * -2e-3, delta=1e-12)

    def check_jacobian_is_derivative(self, tangents):
        K, x, b = loaded_point(tangents)
        R = K @ x - b
        at = FrictionPoint(x, R, np.zeros(9), np.diag(K).copy(), 1.0, tangents)
        self.assertTrue(friction_term(constraints()[0], at).projection.stick)
        self.assertFalse(friction_term(constraints()[1], at).projection.stick)
        self.assertGreater(friction_term(constraints()[1], at).bound, 0.0)
        self.assertFalse(friction_term(constraints()[2], at).closed)
        # on a sparse K (the full path's) and a dense one (the condensed H)
        A = petsc_matrix(K)
        J = A.duplicate(copy=True)
        J.setOption(PETSc.Mat.Option.NEW_NONZERO_ALLOCATION_ERR, False)
        friction_jacobian(constraints(), at, A, J)
        G = J.convert("dense").getDenseArray()
        H = A.convert("dense")
        G_dense = H.duplicate(copy=True)
        friction_jacobian(constraints(), at, H, G_dense)
        self.assertTrue(np.allclose(G_dense.getDenseArray(), G, rtol=1e-13, atol=1e-13))
        F, h = residual(K, b, x, tangents), 1e-7
        for j in range(9):
            # one-sided into the bound for the normals (x_N > 1 stays closed)
            y = x.copy()
            y[j] += h
            difference = (residual(K, b, y, tangents) - F) / h
            for i in range(9):
                self.assertAlmostEqual(G[i, j], difference[i], delta=1e-5 * (1 + abs(G[i, j])), msg=f"J({i}, {j})")

    def test_jacobian_is_the_derivative_2d(self):
        self.check_jacobian_is_derivative(1)

    def test_jacobian_is_the_derivative_3d(self):
        self.check_jacobian_is_derivative(2)


if __name__ == "__main__":
    unittest.main()
