"""Unit tests of the prototype's change of variables
(python_prototype/contact/change_of_variables.py), the twins of
tests/unit/test_change_of_variables.cpp: T_node's rows are the normals
completed orthonormally, so each Signorini constraint nu_j . u <= g_j is the
bound w_j <= g_j on w = T u; dependent normals and a change that would mix a
prescribed component are refused; a fault's pair block makes the jump and
the mean the new variables; on a system, A' = T^{-T} A T^{-1} is the
same energy and its residual holds the constraints' multipliers."""
import math
import os
import sys
import unittest

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
import support  # noqa: E402,F401  (the repository on sys.path)
from python_prototype.contact.change_of_variables import (  # noqa: E402
    ChangeOfVariables, JunctionPair, coordinate_axis, junction_change_of_variables, node_change_of_variables,
    pair_change_of_variables)
from dense import petsc_matrix, petsc_vector, spd_matrix  # noqa: E402

FREE = [False, False, False]
ANGLE = math.pi / 6  # a foundation inclined at 30 degrees


def normalised(*v):
    return list(np.array(v, dtype=float) / np.linalg.norm(v))


class NodeChangeOfVariables(unittest.TestCase):
    def test_one_foundation_is_a_rotation(self):
        # 2D, a foundation inclined at 30 degrees; 3D, a normal along no axis.
        for normal, d in (([math.sin(ANGLE), -math.cos(ANGLE), 0.0], 2), (normalised(1, -2, 2), 3)):
            T = node_change_of_variables([normal], d, FREE)
            self.assertIsNotNone(T)
            np.testing.assert_array_equal(T[0], normal[:d], "the first row is the normal")
            np.testing.assert_allclose(T @ T.T, np.eye(d), rtol=0, atol=1e-15)

    def test_inclined_foundation_bound_is_the_gap(self):
        # u . nu <= g is w_0 <= g: a node lying on the foundation (u = g nu
        # plus any tangential slip s tau) has w_0 = g, and the slip is all in w_1.
        gap = 1.2e-3
        round_off = 1e-14 * gap
        nu = np.array([math.sin(ANGLE), -math.cos(ANGLE)])
        tau = np.array([math.cos(ANGLE), math.sin(ANGLE)])
        T = node_change_of_variables([list(nu) + [0.0]], 2, FREE)
        for slip in (0.0, 1e-3, -5e-3):
            on = gap * nu + slip * tau
            w = T @ on
            self.assertAlmostEqual(w[0], gap, delta=round_off, msg=f"slip {slip}")
            self.assertAlmostEqual(abs(w[1]), abs(slip), delta=round_off, msg=f"slip {slip}")
            # Half the gap closed: inside the bound by half the gap.
            self.assertAlmostEqual((T @ (on - gap / 2 * nu))[0], gap / 2, delta=round_off)

    def test_two_foundations_at_one_node(self):
        # Two foundations 36.87 degrees apart meet at the node: the first two
        # rows are their normals (not orthogonal), the third the tangent they
        # share, and u = T^{-1} (g_1, g_2, s) touches both.
        n1, n2 = [0.0, -1.0, 0.0], [0.6, -0.8, 0.0]
        T = node_change_of_variables([n1, n2], 3, FREE)
        np.testing.assert_array_equal(T[0], n1)
        np.testing.assert_array_equal(T[1], n2)
        tangent = T[2]
        self.assertAlmostEqual(tangent @ tangent, 1.0, delta=1e-15)
        self.assertAlmostEqual(T[0] @ tangent, 0.0, delta=1e-15)
        self.assertAlmostEqual(T[1] @ tangent, 0.0, delta=1e-15)
        g1, g2 = 1e-3, 2e-3
        corner = np.linalg.solve(T, [g1, g2, 0.7])
        self.assertAlmostEqual(T[0] @ corner, g1, delta=1e-15)
        self.assertAlmostEqual(T[1] @ corner, g2, delta=1e-15)
        # In 2D two foundations leave nothing to complete: T is their normals.
        np.testing.assert_array_equal(node_change_of_variables([n1, n2], 2, FREE), [n1[:2], n2[:2]])

    def test_dependent_normals_are_refused(self):
        n = normalised(1, -3, 0)

        def turned(angle):
            return [math.cos(angle) * n[0] - math.sin(angle) * n[1], math.sin(angle) * n[0] + math.cos(angle) * n[1],
                    0.0]
        self.assertIsNone(node_change_of_variables([n, n], 2, FREE), "the same normal twice")
        self.assertIsNone(node_change_of_variables([n, [-n[0], -n[1], 0.0]], 2, FREE), "opposite normals")
        self.assertIsNone(node_change_of_variables([n, turned(1e-10)], 2, FREE), "1e-10 rad apart")
        self.assertIsNotNone(node_change_of_variables([n, turned(1e-3)], 2, FREE), "1e-3 rad apart")
        # Three normals in 3D, the third in the plane of the first two.
        a, b = [0.0, 0.0, -1.0], [0.6, 0.0, -0.8]
        self.assertIsNone(node_change_of_variables([a, b, normalised(0.3, 0, -0.9)], 3, FREE))
        self.assertIsNotNone(node_change_of_variables([a, b, normalised(0.3, 0.2, -0.9)], 3, FREE))

    def test_prescribed_component_is_kept(self):
        # A normal perpendicular to z at a node whose z is prescribed: z stays
        # one of the new variables (a row of T is e_z, and no other row mixes it).
        n = [0.6, -0.8, 0.0]
        T = node_change_of_variables([n], 3, [False, False, True])
        self.assertIsNotNone(T)
        rows = [r for r in range(3) if T[r, 2] != 0]
        self.assertEqual(len(rows), 1)
        self.assertEqual(abs(T[rows[0], 2]), 1.0)
        self.assertEqual(list(T[rows[0], :2]), [0.0, 0.0])
        # x prescribed, but the normal has an x part: the change would mix it.
        self.assertIsNone(node_change_of_variables([n], 3, [True, False, False]))
        self.assertIsNone(node_change_of_variables([n], 2, [True, False, False]))
        # The whole node prescribed: it does not move, any change will do.
        self.assertIsNotNone(node_change_of_variables([n], 3, [True, True, True]))

    def test_coordinate_axis(self):
        self.assertEqual(coordinate_axis([0.0, -1.0, 0.0], 2), (1, -1))
        self.assertEqual(coordinate_axis([0.0, 0.0, 1.0], 3), (2, 1))
        self.assertEqual(coordinate_axis([1e-15, -1.0, 0.0], 2), (1, -1), "round-off")
        self.assertIsNone(coordinate_axis([0.6, -0.8, 0.0], 2))
        self.assertIsNone(coordinate_axis([1e-13, -1.0, 0.0], 2), "more than round-off")
        # A normal along z is no axis of a 2D problem.
        self.assertIsNone(coordinate_axis([0.0, 0.0, 1.0], 2))

    def test_inverse_is_the_inverse(self):
        # The change's T^{-1} (the prototype inverts each block):
        # T^{-1} T = I for blocks that are not orthogonal.
        A = petsc_matrix(spd_matrix(5))
        T2, T3 = np.array([[2, 1], [-0.5, 3]]), np.array([[2, 1, 0], [-1, 3, 0.5], [0.25, -2, 4]])
        for T, d in ((T2, 2), (T3, 3)):
            change = ChangeOfVariables(A, [(list(range(1, 1 + d)), T)], True)
            product = change.T_inverse.convert("dense").getDenseArray() @ change.T.convert("dense").getDenseArray()
            np.testing.assert_allclose(product, np.eye(5), rtol=0, atol=1e-15, err_msg=f"{d}D")

    def test_pair_block_is_jump_and_mean(self):
        # A fault inclined at 30 degrees in 3D: w_J = R (u+ - u-) with R's
        # first row the constraint normal nu = -n, w_M = (u+ + u-) / 2; the
        # inverse is u+- = w_M +- R^T w_J / 2.
        d = 3
        nu = normalised(math.sin(ANGLE), 0, -math.cos(ANGLE))
        R = node_change_of_variables([nu], d, FREE)
        B = pair_change_of_variables(R, d)
        u = np.array([1e-3, -2e-3, 0.5e-3, 0.7e-3, -1e-3, 3e-3])
        jump, mean = u[:d] - u[d:], (u[:d] + u[d:]) / 2
        np.testing.assert_allclose(B @ u, np.concatenate([R @ jump, mean]), rtol=0, atol=1e-18)
        self.assertAlmostEqual((B @ u)[0], np.dot(nu, jump), delta=1e-18, msg="the bounded jump is nu.[u]")
        I = np.eye(d)
        np.testing.assert_allclose(np.linalg.inv(B), np.block([[R.T / 2, I], [-R.T / 2, I]]), rtol=0, atol=1e-15)


def x_junction():
    """An X junction in 2D: pieces 0 and 1 above fault A (normal nA into
    them), 2 and 3 below; B (normal nB) has 1 and 3 on its + side. Its four
    pairs: A's arms (+0, -2), (+1, -3), B's arms (+1, -0), (+3, -2), piece
    1 on the + side of two (rows 0 and 1)."""
    nA = -np.array(normalised(-math.sin(math.pi / 6), math.cos(math.pi / 6), 0))
    nB = -np.array(normalised(math.cos(math.pi / 9), math.sin(math.pi / 9), 0))
    return [JunctionPair(0, 2, 0, nA), JunctionPair(1, 3, 0, nA), JunctionPair(1, 0, 1, nB),
            JunctionPair(3, 2, 0, nB)]


class JunctionChangeOfVariables(unittest.TestCase):
    def test_junction_rows_are_the_normal_jumps(self):
        # Each pair's row of w = B u is nu . (u+ - u-); the other rows are
        # orthonormal and orthogonal to those; B is invertible.
        d, m = 2, 4
        pairs = x_junction()
        B = junction_change_of_variables(pairs, m, d, np.zeros(m * d, dtype=bool))
        u = np.array([1e-3, -2e-3, 0.5e-3, 0.7e-3, -1e-3, 3e-3, 2e-3, -0.4e-3])
        rows = [d * p.plus + p.row for p in pairs]
        for p, row in zip(pairs, rows):
            jump = u[d * p.plus:d * p.plus + d] - u[d * p.minus:d * p.minus + d]
            self.assertAlmostEqual((B @ u)[row], np.dot(p.normal[:d], jump), delta=1e-18, msg=f"row {row}")
        free = [r for r in range(m * d) if r not in rows]
        np.testing.assert_allclose(B[free] @ B.T, np.eye(m * d)[free], rtol=0, atol=1e-14)
        np.testing.assert_allclose(np.linalg.inv(B) @ B, np.eye(m * d), rtol=0, atol=1e-12)

    def test_junction_of_dependent_constraints_is_refused(self):
        # The same constraint twice (in another row), or two pairs in one row.
        pairs = x_junction()
        pairs.append(JunctionPair(0, 2, 1, pairs[0].normal))
        none = np.zeros(8, dtype=bool)
        self.assertIsNone(junction_change_of_variables(pairs, 4, 2, none))
        pairs = x_junction()
        pairs[2].row = 0
        self.assertIsNone(junction_change_of_variables(pairs, 4, 2, none))

    def test_junction_keeps_prescribed_components(self):
        # Two vertical planes crossing in 3D (the X of x_junction in the x-y
        # plane) on a boundary whose z is held: each node's z row is its unit
        # vector, and no other row reaches a z DOF, so the Dirichlet rows stay
        # their own; holding an x as well (along a normal) is refused.
        d, m = 3, 4
        held = np.zeros(m * d, dtype=bool)
        held[2::d] = True
        B = junction_change_of_variables(x_junction(), m, d, held)
        np.testing.assert_array_equal(B[:, 2::d], np.eye(m * d)[:, 2::d])
        np.testing.assert_allclose(np.linalg.inv(B) @ B, np.eye(m * d), rtol=0, atol=1e-12)
        held[0] = True
        self.assertIsNone(junction_change_of_variables(x_junction(), m, d, held))


class ChangeOfVariablesSystem(unittest.TestCase):
    """A system of 6 nodes in 2D (12 DOFs) with two transformed nodes and a
    fault's node pair: node 0 on a foundation inclined at 30 degrees, node 2
    on two foundations, nodes 3 (+) and 5 (-) the two faces of a fault
    inclined at 60 degrees."""
    x = np.array([1e-3, -2e-3, 0.5e-3, 0.7e-3, -1e-3, 3e-3, 2e-3, -0.4e-3, 1.5e-3, 0.2e-3, -0.8e-3, 0.9e-3])
    b = np.array([1, -2, 0.5, 3, -1, 0.25, 2, -4, 1.5, -0.5, 0.75, 2.5])

    def setUp(self):
        self.d = 2
        inclined = [math.sin(ANGLE), -math.cos(ANGLE), 0.0]
        fault = [-math.cos(ANGLE), -math.sin(ANGLE), 0.0]
        self.nodes = [([0, 1], node_change_of_variables([inclined], 2, FREE)),
                      ([4, 5], node_change_of_variables([[0.0, -1.0, 0.0], [0.6, -0.8, 0.0]], 2, FREE)),
                      ([6, 7, 10, 11], pair_change_of_variables(node_change_of_variables([fault], 2, FREE), 2))]
        self.A = spd_matrix(12)
        self.T = np.eye(12)
        for dofs, block in self.nodes:
            self.T[np.ix_(dofs, dofs)] = block
        self.petsc_A = petsc_matrix(self.A)
        self.change = ChangeOfVariables(self.petsc_A, self.nodes, True)
        self.At = self.change.congruence(self.petsc_A)

    def test_congruence_is_the_same_energy(self):
        # A' = T^{-T} A T^{-1}, symmetric, and x'^T A' x' = x^T A x for x' = T x.
        inverse = np.linalg.inv(self.T)
        got = self.At.convert("dense").getDenseArray()
        round_off = 1e-14 * np.abs(self.A).max()
        np.testing.assert_allclose(got, inverse.T @ self.A @ inverse, rtol=0, atol=round_off)
        np.testing.assert_allclose(got, got.T, rtol=0, atol=round_off)
        x = petsc_vector(self.petsc_A, self.x)
        xt, back = x.duplicate(), x.duplicate()
        self.change.forward(x, xt)
        self.change.backward(xt, back)
        w = xt.getArray(readonly=True)
        np.testing.assert_allclose(w, self.T @ self.x, rtol=0, atol=1e-18, err_msg="forward")
        np.testing.assert_allclose(back.getArray(readonly=True), self.x, rtol=0, atol=1e-18, err_msg="backward")
        energy = self.x @ self.A @ self.x
        self.assertAlmostEqual(w @ got @ w, energy, delta=1e-14 * energy)

    def test_residual_holds_the_multipliers(self):
        # F' = A' x' - b' with b' = T^{-T} b: in a block's DOFs F = T^T F' =
        # sum_j F'_j (row j of T), elsewhere F' = F.
        x, b = petsc_vector(self.petsc_A, self.x), petsc_vector(self.petsc_A, self.b)
        xt, bt, Ft = x.duplicate(), x.duplicate(), x.duplicate()
        self.change.forward(x, xt)
        self.change.dual(b, bt)
        self.At.mult(xt, Ft)
        Ft.axpy(-1.0, bt)
        F_t = Ft.getArray(readonly=True)
        TtFt = F_t.copy()
        for dofs, block in self.nodes:
            TtFt[dofs] = block.T @ F_t[dofs]
        np.testing.assert_allclose(TtFt, self.A @ self.x - self.b, rtol=0, atol=1e-14 * np.abs(self.b).max())


if __name__ == "__main__":
    unittest.main()
