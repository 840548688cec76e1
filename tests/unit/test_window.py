"""Unit tests of a window's time history (python_prototype/coupling/window.py),
the twins of tests/unit/test_window.cpp: the displacement's path across a
window is the straight line under backward Euler, and under BDF2 the
quadratic through u_{K-1}, u_K and u, exactly at every fine time of an
unequal pair of windows; the first window takes u at once and the second
of q > 1 keeps the straight line; a window's derivative is BDF2 only where
the step before equals its fine step."""
import os
import sys
import unittest

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
import support  # noqa: E402,F401  (the repository on sys.path)
from python_prototype.coupling.window import Window, WindowHistory  # noqa: E402
from python_prototype.scene.input import TimeScheme  # noqa: E402
from python_prototype.time.time_grid import TimeGrid  # noqa: E402

# Two entries: a linear and a rough value, so an entry-wise error shows.
U_BEFORE, U_K, U = np.array([1.0, -2.0]), np.array([3.0, 0.5]), np.array([4.0, 7.0])


def grid():
    """Windows of 2 fine steps of 1 s, then 3 of 0.5 s, then 2 of 1 s:
    t = 0, 1, 2, 2.5, 3, 3.5, 4.5, 5.5."""
    dt = [1, 1, 0.5, 0.5, 0.5, 1, 1]
    return TimeGrid(np.concatenate([[0.0], np.cumsum(dt)]), dt)


def history(scheme, g, j_before):
    h = WindowHistory(scheme, g)
    h.u_K, h.u_before, h.j_before = U_K, U_BEFORE, j_before
    return h


def window(K, j, q):
    return Window(K, j, q, None, None, U_K)


def quadratic(t, x, y):
    """The Lagrange quadratic through (x[a], y[a]) at t."""
    return sum(y[a] * np.prod([(t - x[b]) / (x[a] - x[b]) for b in range(3) if b != a]) for a in range(3))


class WindowHistoryTest(unittest.TestCase):
    def test_backward_euler_path_is_the_straight_line(self):
        g = grid()
        h, w = history(TimeScheme.backward_euler, g, 0), window(1, 2, 3)  # [2, 3.5]
        for m in range(4):
            np.testing.assert_allclose(h.path(w, U, m), U_K + (g.t[2 + m] - 2.0) / 1.5 * (U - U_K), atol=1e-14)
        self.assertTrue(np.array_equal(h.path(w, U, 0), U_K))
        self.assertEqual(h.path(w, U, 3)[1], U[1])

    def test_bdf2_path_is_the_quadratic_through_three_window_ends(self):
        g = grid()
        # The third window [3.5, 5.5] after [2, 3.5]: u_{K-1} at 2, u_K at 3.5.
        h, w = history(TimeScheme.bdf2, g, 2), window(2, 5, 2)
        for m in range(3):
            for i in range(2):
                self.assertAlmostEqual(h.path(w, U, m)[i],
                                       quadratic(g.t[5 + m], [2.0, 3.5, 5.5], [U_BEFORE[i], U_K[i], U[i]]),
                                       delta=1e-13, msg=f"m {m}, entry {i}")

    def test_bdf2_starts_with_the_end_value_and_the_line(self):
        h = history(TimeScheme.bdf2, grid(), 0)
        # The first window: u_0 may be the state before a load at t = 0+.
        first = window(0, 0, 2)
        self.assertTrue(np.array_equal(h.path(first, U, 0), U_K))
        self.assertTrue(np.array_equal(h.path(first, U, 1), U))
        # The second window of q > 1 keeps the straight line.
        self.assertAlmostEqual(h.path(window(1, 2, 3), U, 1)[1], U_K[1] + (0.5 / 1.5) * (U[1] - U_K[1]), delta=1e-14)

    def test_bdf2_only_where_the_step_before_equals_the_fine_step(self):
        g = grid()
        h = history(TimeScheme.bdf2, g, 0)
        self.assertFalse(h.derivative(0, 2).second_order())  # no step before
        self.assertTrue(h.derivative(1, 1).second_order())   # 1 after 1
        self.assertFalse(h.derivative(2, 3).second_order())  # q = 3 of 0.5 after 1
        self.assertTrue(h.derivative(2, 1).second_order())   # q = 1: variable-step BDF2
        self.assertFalse(h.derivative(5, 2).second_order())  # 1 after 0.5, q = 2
        self.assertFalse(history(TimeScheme.backward_euler, g, 0).derivative(1, 1).second_order())


if __name__ == "__main__":
    unittest.main()
