"""Unit tests of a solve's record (python_prototype/steps/solve_record.py),
the twins of tests/unit/test_solve_record.cpp: the l2 norms of each field
and of its change since start(), counting only the values a rank owns
(ghosts and copies left out), NaN for a field the step has not, and the
Newton steps taken in between."""
import math
import os
import sys
import unittest

import numpy as np
from mpi4py import MPI

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
import support  # noqa: E402,F401  (the repository on sys.path)
from python_prototype.steps.solve_record import FieldValues, SolveFields, SolveMeter  # noqa: E402


class SolveRecordTest(unittest.TestCase):
    def test_norms_of_each_field_and_its_change(self):
        # p has 2 owned values and a ghost, u 3 owned; no p_f.
        p, u = np.array([3.0, 4.0, 100.0]), np.array([1.0, 2.0, 2.0])
        meter = SolveMeter()
        meter.start(SolveFields(FieldValues(p, 2), FieldValues(u, 3), FieldValues(), MPI.COMM_WORLD), 7)
        p = np.array([0.0, 4.0, -50.0])  # change (-3, 0): the ghost's -150 not counted
        u = np.array([1.0, 2.0, 4.0])    # change (0, 0, 2)
        r = meter.record(SolveFields(FieldValues(p, 2), FieldValues(u, 3), FieldValues(), MPI.COMM_WORLD), 10, 5)
        self.assertAlmostEqual(r.dp, 3.0, places=15)
        self.assertAlmostEqual(r.p, 4.0, places=15)
        self.assertAlmostEqual(r.du, 2.0, places=15)
        self.assertAlmostEqual(r.u, math.sqrt(21.0), places=15)
        self.assertTrue(math.isnan(r.fault_dp) and math.isnan(r.fault_p), "a step without conduit faults")
        self.assertEqual((r.newton_steps, r.active_nodes), (3, 5))

    def test_a_field_held_by_another_rank_counts_nothing_here(self):
        # p_f held by the last rank: here (one rank) all of it, with owned = 0
        # nothing, as on the other ranks.
        p_f = np.array([1.0, 1.0])
        meter = SolveMeter()
        meter.start(SolveFields(FieldValues(), FieldValues(), FieldValues(p_f, 0), MPI.COMM_WORLD), 0)
        r = meter.record(SolveFields(FieldValues(), FieldValues(), FieldValues(np.array([3.0, 5.0]), 0),
                                     MPI.COMM_WORLD), 0, 0)
        self.assertEqual((r.fault_dp, r.fault_p), (0.0, 0.0))
        self.assertTrue(math.isnan(r.dp) and math.isnan(r.du))


if __name__ == "__main__":
    unittest.main()
