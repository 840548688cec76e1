"""Unit tests of the prototype's cycle of a coupling iteration
(python_prototype/coupling/cycle.py), the twins of tests/unit/test_cycle.cpp:
a contact set returning every P iterations with increments that do not
shrink is a cycle of period P, the smallest; a set that stays, increments
that shrink by more than 0.05 % a period, or too few iterations are none."""
import os
import sys
import unittest

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
import support  # noqa: E402,F401  (the repository on sys.path)
from python_prototype.coupling.cycle import cycle_period  # noqa: E402


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


if __name__ == "__main__":
    unittest.main()
