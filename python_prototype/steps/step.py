"""The interface of a step, whichever system it solves (the flow, the
mechanics, or flow and mechanics together): what the schemes, checkpoints
and the output ask of any step, so that none of them branches on which
physics a scene has (cpp/steps/step.h)."""
import abc
from dataclasses import dataclass
from typing import Optional

import numpy as np

from ..contact.contact_state import ActiveSet
from ..solvers.solver import SolverError
from .solve_record import SolveMeter

# The functions of a step that a checkpoint keeps besides its unknowns (the
# time scheme's memory): (checkpoint name, Function) pairs.
History = list


@dataclass
class StepState:
    """The state of a step at its start: its unknowns, to go back to when
    the step is retried, and its pressure and displacement (None where it
    has none), BDF2's memory once the step is accepted."""
    unknowns: np.ndarray
    p: Optional[np.ndarray] = None
    u: Optional[np.ndarray] = None


class Step(abc.ABC):
    """One step of a time-stepping scheme on one system (`system`, a
    steps/system.py System): advances its unknowns from t_{k-1} to t_k.

    A scheme with one solve per step (coupling/single_solve.py) drives any
    step through advance(); the fixed-stress split drives the flow and the
    mechanics step through their own interfaces, which iterate between them."""

    assembly_time = 0.0  # right-hand sides

    def __init__(self):
        self._meter = SolveMeter()
        self._solves = []

    @abc.abstractmethod
    def name(self):
        """The system's name in summary.json and in checkpoints."""

    @abc.abstractmethod
    def advance(self, t, d):
        """Solves the step to time t with the time derivative `d`
        (time_scheme.py) from the state the step holds."""

    def time_step_changed(self):
        """The "dt" constant changed (parameters.py, set_time_step): rebuilds
        what depends on it."""

    def equilibrate(self):
        """mechanics.initial_equilibrium: replaces u = 0 by the displacement
        in equilibrium with the loads at t = 0 and the initial pressure
        (nothing for a step without mechanics); what its solve measured (its
        rows of iterations.csv at step 0)."""
        return []

    def begin_step(self):
        """A time step (or a window of the fixed-stress split) starts from
        the current unknowns: friction measures its slip increments from
        them, a conduit fault its pressure's change (nothing without
        either)."""

    @abc.abstractmethod
    def state(self):
        """The StepState now (at the start of a step)."""

    def restore(self, start):
        """Back to the StepState `start`."""
        self.set_unknowns(start.unknowns)

    def arrays(self):
        """State in plain arrays, the same on every rank, that a checkpoint
        keeps (the conduit faults' pressure; none by default; collective):
        name -> array."""
        return {}

    def restore_arrays(self, arrays):
        """Restores arrays() from a checkpoint's arrays."""

    def keep_history(self, start):
        """The step from `start` was accepted: it becomes the state one step
        before the next (BDF2's memory)."""

    def accept(self, t):
        """The step's solution at t (loaded in the step) was accepted: what
        the step adds up over the run takes it (a conduit fault's volumes)."""

    def unbalanced(self, t):
        """Whether the step's solution at t (loaded in the step) conserves
        what it must to be accepted: one line naming what does not (a
        conduit fault whose volumes do not balance), empty when all does."""
        return ""

    def solves(self):
        """What each solve of the last advance measured, in order, also when
        it failed: one SolveRecord, or one per iteration of the monolithic
        step on its conduit faults' apertures (iterations.csv)."""
        return self._solves

    def iterations(self):
        """The solves of the last advance, which the progress line shows."""
        return len(self._solves)

    @abc.abstractmethod
    def solve_fields(self):
        """The fields the step's solves move (p, u, p_f: a SolveFields), for
        their records."""

    def solve_begins(self, first):
        """Brackets each solve of advance(); the first of an advance clears
        the last one's records."""
        if first:
            self._solves = []
        self._meter.start(self.solve_fields(), self.system.newton_steps())

    def solve_ends(self):
        """(collective: the record counts active nodes)"""
        self._solves.append(self._meter.record(self.solve_fields(), self.system.newton_steps(),
                                               self.active_contact_set().nodes))

    def recorded_solve(self, first, solve):
        """Runs `solve` as one solve of advance(), between solve_begins(first)
        and solve_ends(); one that fails (SolverError) leaves its record too,
        its Newton steps and no change, before its error goes on: the rows of
        iterations.csv show what a failed step spent. Returns what `solve`
        returns."""
        self.solve_begins(first)
        try:
            result = solve()
        except SolverError:
            self._solves.append(self._meter.failed(self.system.newton_steps(), self.active_contact_set().nodes))
            raise
        self.solve_ends()
        return result

    @abc.abstractmethod
    def unknowns(self):
        """The unknowns (ghosts included)."""

    @abc.abstractmethod
    def set_unknowns(self, x):
        """Restores the unknowns."""

    @abc.abstractmethod
    def parts(self):
        """The fields within unknowns() (UnknownsPart), for a checkpoint."""

    def history(self):
        """The time scheme's memory a checkpoint keeps (History; empty by default)."""
        return []

    def pressure_values(self):
        """The pressure now (None where the step has none)."""
        return None

    def displacement_values(self):
        """The displacement now (None where the step has none)."""
        return None

    def same_contact_set(self, before):
        """Whether the contact active set is `before` (collective; True
        without contact)."""
        return True

    def active_contact_set(self):
        """The contact active set now (empty without contact; collective)."""
        return ActiveSet()
