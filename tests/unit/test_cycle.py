"""Unit tests of the prototype's cycle and stagnation of a coupling iteration
(python_prototype/coupling/cycle.py), the twins of tests/unit/test_cycle.cpp:
a contact set returning every P iterations with increments that do not
shrink is a cycle of period P, the smallest; a set that stays, increments
that shrink by more than 0.05 % a period, or too few iterations are none.
A steady rate that cannot reach the tolerance in the iterations left
stagnates; a faster, unsteady or early one does not."""
import os
import sys
import unittest

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
import support  # noqa: E402,F401  (the repository on sys.path)
from python_prototype.coupling.cycle import FIRST_JUDGED, cycle_period, stagnates  # noqa: E402


def repeated(pattern, periods, rate):
    """`periods` repetitions of `pattern`, increments scaled by `rate` per period."""
    active = [a for _ in range(periods) for a in pattern]
    increments = [rate ** k * (1.0 + i) for k in range(periods) for i in range(len(pattern))]
    return active, increments


class CycleTests(unittest.TestCase):
    def test_period_of_the_contact_set(self):
        self.assertEqual(cycle_period(*repeated([117, 117, 118, 118], 3, 1.0)), 4)
        self.assertEqual(cycle_period(*repeated([52, 57], 3, 1.0)), 2)
        self.assertEqual(cycle_period(*repeated([271, 274, 274], 3, 0.9998)), 3)
        self.assertEqual(cycle_period(*repeated([117, 117, 118, 118], 3, 1.5)), 4)

    def test_none_where_the_iteration_progresses(self):
        self.assertEqual(cycle_period(*repeated([117, 117, 118, 118], 3, 0.998)), 0)
        self.assertEqual(cycle_period(*repeated([118, 118, 118, 118], 3, 1.0)), 0)
        self.assertEqual(cycle_period(*repeated([117, 117, 118, 118], 2, 1.0)), 0)
        active, increments = repeated([117, 117, 118, 118], 3, 1.0)
        active[-3] = 116
        self.assertEqual(cycle_period(active, increments), 0)
        self.assertEqual(cycle_period([], []), 0)


def geometric(n, rate):
    """`n` increments from 1e-3 shrinking by `rate` each."""
    return [1e-3 * rate ** i for i in range(n)]


class StagnationTests(unittest.TestCase):
    def test_steady_rate_too_slow_for_the_iterations_left(self):
        # At 0.983 from 1e-3 * 0.983^14 = 7.9e-4, 1e-10 takes 942 iterations.
        slow = geometric(15, 0.983)
        self.assertTrue(stagnates(slow, 1e-10, 385))
        self.assertFalse(stagnates(slow, 1e-10, 1000))  # within the iterations left
        self.assertFalse(stagnates(slow, 1e-3, 385))    # converged already
        # The split's alternating ratios at fault_reactivation's step 53 (0.9819, 0.9826).
        alternating = list(slow)
        for i in range(1, len(alternating)):
            alternating[i] = alternating[i - 1] * (0.9819 if i % 2 else 0.9826)
        self.assertTrue(stagnates(alternating, 1e-10, 385))

    def test_none_where_the_rate_is_fast_unsteady_or_early(self):
        self.assertFalse(stagnates(geometric(15, 0.85), 1e-10, 2))  # below STAGNANT_RATE
        self.assertFalse(stagnates(geometric(FIRST_JUDGED - 1, 0.99), 1e-10, 50))  # too early
        self.assertFalse(stagnates(geometric(15, 1.01), 1e-10, 50))  # growing: not a rate below 1
        self.assertFalse(stagnates(geometric(15, 0.9999), 1e-10, 50))  # above SLOWEST_RATE: gamma near 1
        unsteady = geometric(15, 0.97)
        unsteady[12] *= 0.9  # one ratio 0.873, the next 1.078
        self.assertFalse(stagnates(unsteady, 1e-10, 50))
        self.assertFalse(stagnates([], 1e-10, 50))


if __name__ == "__main__":
    unittest.main()
