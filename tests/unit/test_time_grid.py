"""Unit tests of the prototype's time grid (python_prototype/time/time_grid.py)
and the scene's times (Scene.times, stops, is_output_time), the twins of
tests/unit/test_time_grid.cpp: fixed steps kept exactly, geometric growth
ending on time.end, halving exact in binary floating point, time.retry
counted and refused after the allowed attempts, and planned steps equal
between stops and landing on every one."""
import copy
import math
import os
import sys
import types
import unittest

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
import support  # noqa: E402,F401  (the repository on sys.path)
from python_prototype.scene.scene import AdaptiveSpec, Scene  # noqa: E402
from python_prototype.time.time_grid import (FailedStep, TimeGrid, halve_steps, plan_steps, retry_step,  # noqa: E402
                                             time_grid)

CAUSE = "the coupling did not converge"


def timed(end, dt, growth=1.0):
    return Scene(end_time=end, dt=dt, growth=growth)


class TimeGridTest(unittest.TestCase):
    def expect_consistent(self, g):
        """t increases strictly, and each dt is its step to round-off."""
        self.assertEqual(len(g.t), len(g.dt) + 1)
        self.assertEqual(g.t[0], 0.0)
        for k in range(g.steps()):
            self.assertGreater(g.t[k + 1], g.t[k], f"step {k}")
            self.assertAlmostEqual(g.t[k + 1] - g.t[k], g.dt[k], delta=1e-14 * g.t[-1], msg=f"step {k}")

    def test_fixed_steps_are_whole_multiples_kept_exactly(self):
        # 0.3 / 0.1 is 2.9999999999999996 in binary: still 3 steps, and each
        # step is dt itself, whatever the round-off of the times' differences.
        s = timed(0.3, 0.1)
        g = time_grid(s)
        self.assertEqual(g.steps(), 3)
        self.assertEqual(s.num_steps(), 3)
        for k in range(3):
            self.assertEqual(g.dt[k], 0.1, f"step {k}")
            self.assertEqual(g.t[k + 1], (k + 1) * 0.1, f"time {k + 1}")
        self.expect_consistent(g)

    def test_growth_is_geometric_and_ends_on_the_end(self):
        # dt_k = dt growth^k until time.end: dt (1.5^N - 1) / 0.5 >= 2 first at
        # N = ceil(log 11 / log 1.5) = 6, the last step cut short to land on 2.
        s = timed(2.0, 0.1, 1.5)
        g = time_grid(s)
        N = math.ceil(math.log(11.0) / math.log(1.5))
        self.assertEqual(g.steps(), N)
        self.assertEqual(s.num_steps(), N)
        self.assertEqual(g.t[-1], 2.0)
        for k in range(N - 1):
            self.assertAlmostEqual(g.dt[k], 0.1 * 1.5 ** k, delta=1e-14 * s.end_time, msg=f"step {k}")
        self.assertLessEqual(g.dt[-1], 0.1 * 1.5 ** (N - 1))
        self.expect_consistent(g)

    def test_halve_steps_is_exact(self):
        # Halving steps 1 and 2 of five steps of 0.1: seven steps, the halves
        # exactly dt/2 and summing back to dt, the other times unchanged.
        g = time_grid(timed(0.5, 0.1))
        before = copy.deepcopy(g)
        halve_steps(g, 1, 2)
        self.assertEqual(g.steps(), 7)
        self.assertEqual(g.dt, [0.1, 0.05, 0.05, 0.05, 0.05, 0.1, 0.1])
        self.assertEqual(g.dt[1] + g.dt[2], before.dt[1])
        self.assertEqual(g.t[2], before.t[1] + before.dt[1] / 2)
        for now, then in ((0, 0), (1, 1), (3, 2), (5, 3), (6, 4), (7, 5)):
            self.assertEqual(g.t[now], before.t[then], f"time {then} kept")
        self.expect_consistent(g)

    def test_retry_is_counted_and_refused_after_the_allowed_attempts(self):
        s = timed(1.0, 0.25)
        s.retry = 2
        g = time_grid(s)
        attempts, report = [0], types.SimpleNamespace(retries=0)
        first = retry_step(s, FailedStep(3, CAUSE, 2, 1), attempts, report, g)
        self.assertIsNotNone(first)
        for part in ("step 3", CAUSE, "retry 1 of 2"):
            self.assertIn(part, first)
        self.assertEqual((attempts[0], report.retries), (1, 1))
        self.assertEqual(g.steps(), 5)
        self.assertEqual(g.dt[2], 0.125)

        second = retry_step(s, FailedStep(3, CAUSE, 2, 2), attempts, report, g)
        self.assertIn("retry 2 of 2", second)
        self.assertEqual(g.steps(), 7)
        self.assertEqual(g.dt[2], 0.0625)

        kept = list(g.t)
        self.assertIsNone(retry_step(s, FailedStep(3, CAUSE, 2, 4), attempts, report, g))
        self.assertEqual((attempts[0], report.retries), (2, 2))
        self.assertEqual(g.t, kept, "a refused retry leaves the grid")

    def test_no_retry_without_time_retry(self):
        s = timed(1.0, 0.25)
        g = time_grid(s)
        attempts, report = [0], types.SimpleNamespace(retries=0)
        self.assertIsNone(retry_step(s, FailedStep(1, "a solver failed", 0, 1), attempts, report, g))
        self.assertEqual((attempts[0], report.retries), (0, 0))
        self.assertEqual(g.steps(), 4)

    def test_planned_steps_land_on_every_stop(self):
        # n = ceil((stop - t) / h) equal steps to each stop: 3 to 0.25, 4 to
        # 0.6, 4 to 1 with h = 0.1, none longer than h, each stop hit exactly.
        g = TimeGrid([0.0], [])
        stops = [0.25, 0.6, 1.0]
        plan_steps(g, 0, 0.1, stops)
        self.assertEqual(g.steps(), 11)
        last = [3, 7, 11]  # the index of each stop in t
        for j, stop in enumerate(stops):
            self.assertEqual(g.t[last[j]], stop)
            begin = 0 if j == 0 else last[j - 1]
            for k in range(begin, last[j]):
                self.assertEqual(g.dt[k], g.dt[begin], f"equal steps to {stop}")
                self.assertLessEqual(g.dt[k], 0.1)
        self.expect_consistent(g)

    def test_planning_keeps_the_past(self):
        # Replanning after t_3 = 0.3 with h = 0.25: stop 0.2 is behind, one
        # step of 0.2 to 0.5, then two of 0.25 to 1.
        g = time_grid(timed(1.0, 0.1))
        before = copy.deepcopy(g)
        plan_steps(g, 3, 0.25, [0.2, 0.5, 1.0])
        self.assertEqual(g.steps(), 6)
        self.assertEqual(g.t[:4], before.t[:4])
        self.assertEqual((g.t[4], g.t[6]), (0.5, 1.0))
        self.assertEqual(g.dt[4:], [0.25, 0.25])
        self.expect_consistent(g)

    def test_whole_steps_planned_without_a_sliver(self):
        # 2.1 / 0.3 is 7.000000000000001 in binary: 7 steps of 0.3, not 8.
        g = TimeGrid([0.0], [])
        plan_steps(g, 0, 0.3, [2.1])
        self.assertEqual(g.steps(), 7)
        self.assertEqual(g.t[-1], 2.1)
        self.assertAlmostEqual(g.dt[0], 0.3, delta=1e-15)

    def test_adaptive_grid_lands_on_the_output_times(self):
        # time.adaptive: steps of at most time.dt planned to every output time
        # and time.end (output_times holds time.end, as read_scene makes it).
        s = timed(1.0, 0.2)
        s.adaptive = AdaptiveSpec(1e-3, 1e-6, 1.0)
        s.output_times = [0.3, 0.5, 1.0]
        self.assertEqual(s.stops(), s.output_times)
        g = time_grid(s)
        for stop in s.output_times:
            self.assertIn(stop, g.t)
        for dt in g.dt:
            self.assertLessEqual(dt, 0.2)
        self.expect_consistent(g)

    def test_stops_and_output_times(self):
        s = timed(1.0, 0.1)
        self.assertEqual(s.stops(), [1.0], "no output times: time.end alone")
        self.assertTrue(s.is_output_time(0.1), "no output times: every step is written")
        s.output_times = [0.5, 1.0]
        self.assertTrue(s.is_output_time(0.5 + 1e-12), "within 1e-9 time.end")
        self.assertFalse(s.is_output_time(0.5 + 1e-6))
        self.assertFalse(s.is_output_time(0.7))
        self.assertTrue(s.is_output_time(time_grid(s).t[-1]))


if __name__ == "__main__":
    unittest.main()
