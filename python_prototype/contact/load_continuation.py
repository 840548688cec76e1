"""Continuation in the load (cpp/contact/load_continuation.h): a contact
solve that fails from its start is approached from the last load the solver
solved, through loads between (docs/theory.md, "Friction"). It knows no
physics: a solve of the VI at a load, and the last solved load and
solution."""
from ..solvers.solver import SolverError

# The solves a continuation takes at most: halving steps from 1/2 reach a
# load whose last step needs 1/8 in about 12.
CONTINUATION_SOLVES = 12


class SolvedLoad:
    """The last load a VI was solved for and its solution (in the VI's
    unknowns), while its operator stays the one they were solved with."""

    def __init__(self):
        self.load = self.solution = None
        self.known = False

    def keep(self, b, x):
        """b and x solve the VI."""
        if self.load is None:
            self.load, self.solution = b.duplicate(), x.duplicate()
        b.copy(self.load)
        x.copy(self.solution)
        self.known = True

    def forget(self):
        """The operator changed: (b, x) no longer solve it."""
        self.known = False


def continue_load(start, target, x, solve, max_solves):
    """Solves the VI at `target` by `solve(b, x)` (which raises SolverError
    when it fails, leaving its x as it was) along b(tau) = b_0 + tau
    (target - b_0) from the SolvedLoad `start` (b_0, x_0): tau advances by
    1/2, and by half of the last advance after a failure, at most
    `max_solves` solves and not below 1/64. Where tau reaches 1, x holds
    the solution and it returns True; else x is unchanged."""
    b, y = target.duplicate(), start.solution.copy()
    # The solution is piecewise smooth in the load: where a step's states
    # change too much for one Newton solve, a shorter step changes fewer.
    tau, advance, solves = 0.0, 0.5, 0
    while tau < 1 and advance >= 1 / 64 and solves < max_solves:
        solves += 1
        following = min(1.0, tau + advance)
        start.load.copy(b)
        b.axpby(following, 1 - following, target)
        try:
            solve(b, y)
            tau = following
        except SolverError:
            advance /= 2
    if tau >= 1:
        y.copy(x)
    b.destroy()
    y.destroy()
    return tau >= 1
