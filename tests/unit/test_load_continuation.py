"""Unit tests of the prototype's continuation in the load
(python_prototype/contact/load_continuation.py), the twins of
tests/unit/test_load_continuation.cpp: with a solve that converges only
from within `reach` of its solution (the identity: x = b), from the solved
load 0 to 1, steps of 1/2 fail and quarters pass (0.25, 0.5, 0.75, 1: the
solution 1); a reach below the smallest step (1/64), or too few solves,
leaves x as it was; every solve starts where the last passed."""
import os
import sys
import unittest

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
import support  # noqa: E402,F401  (the repository on sys.path)
from petsc4py import PETSc  # noqa: E402
from python_prototype.contact.load_continuation import SolvedLoad, continue_load  # noqa: E402
from python_prototype.solvers.solver import SolverError  # noqa: E402


def scalar(a):
    v = PETSc.Vec().createSeq(1, comm=PETSc.COMM_SELF)
    v.set(a)
    return v


class Reach:
    """Solves x = b from x (in place) when |b - x| <= reach."""

    def __init__(self, reach):
        self.reach, self.tried, self.passed = reach, [], []

    def __call__(self, b, x):
        self.tried.append(b[0])
        if abs(b[0] - x[0]) > self.reach:
            raise SolverError("out of reach")
        b.copy(x)
        self.passed.append(b[0])


def continued(solve, max_solves):
    """Continues from the solved load 0 to the load 1."""
    solved, x = SolvedLoad(), scalar(-7)
    solved.keep(scalar(0), scalar(0))
    return continue_load(solved, scalar(1), x, solve, max_solves), x[0]


class LoadContinuationTests(unittest.TestCase):
    def test_reaches_the_load_in_shorter_steps(self):
        solve = Reach(0.3)
        self.assertEqual(continued(solve, 12), (True, 1.0))
        self.assertEqual(solve.passed, [0.25, 0.5, 0.75, 1.0])
        self.assertEqual(solve.tried[0], 0.5)

    def test_leaves_x_where_it_cannot_reach(self):
        short_reach = Reach(0.01)
        self.assertEqual(continued(short_reach, 12), (False, -7.0))
        self.assertEqual(short_reach.passed, [])
        few = Reach(0.3)
        self.assertEqual(continued(few, 3), (False, -7.0))
        self.assertEqual(few.passed, [0.25, 0.5])

    def test_forgets_when_the_operator_changes(self):
        solved = SolvedLoad()
        self.assertFalse(solved.known)
        solved.keep(scalar(2), scalar(2))
        self.assertTrue(solved.known)
        self.assertEqual(solved.load[0], 2.0)
        solved.forget()
        self.assertFalse(solved.known)


if __name__ == "__main__":
    unittest.main()
