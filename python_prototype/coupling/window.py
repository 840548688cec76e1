"""A window of the fixed-stress split, [t_K, t_{K+1}]: q fine flow steps and
one mechanics step (paper section 4; cpp/coupling/window.h). Its iterates,
and what the time scheme keeps of the windows before it: the flow's time
history and the displacement's path across the window (backward Euler or
BDF2, docs/theory.md "Time schemes")."""
import dataclasses
import math

import numpy as np

from ..contact.contact_state import ActiveSet
from .anderson import AndersonAcceleration
from ..scene.input import TimeScheme
from ..time.time_scheme import TimeDerivative, history_value, time_derivative


class Window:
    """One window's iterates: p^{n,m} and p^{n+1,m} (m = 0..q; m = 0 is p_K),
    u^n and u^{n+1}, the mixed states (z, p)^{n+1,m}, and what the
    contraction measure and the error message carry from one iteration to
    the next."""

    def __init__(self, K, j, q, w_K, p_K, u_K):
        self.K = K                    # the window [t_K, t_{K+1}]
        self.j, self.q = j, q         # its first fine step and its fine steps: t_K = t_j, t_{K+1} = t_{j+q}
        self.active = ActiveSet()     # contact active set of u^{n+1} (the last iteration's)
        self.contact_changed = False  # converged active != the set at t_K
        self.derivative = TimeDerivative()  # of every fine step (time_scheme.py)
        self.w_K = w_K                # flow state (z, p) at t_K, for a retry
        self.p_old = [p_K] * (q + 1)
        self.p_new = [p_K] * (q + 1)
        self.w_new = [None] * (q + 1)
        self.u_old, self.u_new = u_K, None
        self.fault_old = self.fault_new = None  # the conduit faults' p_f^{n,m} and p_f^{n+1,m} (m = 0..q)
        self.anderson = None
        self.accelerated = False  # Anderson's took part in the window (its ratios are not G's)
        self.active_set_changes = 0   # at the last Anderson restart
        self.dsigma_previous, self.dsigma_first = math.nan, 0.0
        self.fault_previous = math.nan  # ||dp_f|| of the last iteration
        self.newton_steps = 0          # of the last mechanics pass's contact solve
        self.increment = 1.0          # max(dp, du) of the last iteration
        self.log = []                 # the last iterations, for the error message
        self.active_nodes = []        # per iteration: the contact set's active nodes (coupling/cycle.py)
        self.increments = []          # per iteration: max(dp, du)
        self.cycle = 0                # the period of the cycle that ended the iteration, 0 for none
        self.flags = []               # the active sets of the last iterations (pins.py), this rank's
        self.pins = np.zeros(0, dtype=np.int8)  # the contact constraints' pins (pins.py), this rank's
        self.pin_rounds = 0           # rounds of pins so far; -1: released after MAX_PIN_ROUNDS
        self.pinned_at = 0            # the iterations before the last pins (their records cleared)


@dataclasses.dataclass
class WindowFailure:
    """What the one-line error of a window that failed says besides the
    window's own record: the time it ended at, the iteration limit, the
    scheme's advice (gamma and what converges instead) and whether to
    propose time.retry (a scene with contact that does not retry)."""
    t: float
    max_iterations: int
    advice: str
    propose_retry: bool = False


def not_converged_message(w, failure):
    """The one-line error of window w that did not converge in
    max_iterations or cycled (cycle.py), with its last three increments."""
    if w.cycle:
        head = (f"the fixed-stress split cycles at t = {failure.t:g} (step {w.K + 1}): after "
                f"{w.pinned_at + len(w.increments)} iterations the contact set returns every {w.cycle} iterations "
                f"(active nodes {' '.join(str(a) for a in w.active_nodes[-w.cycle:])}) and the increments no longer "
                f"shrink{', pinned or not' if w.pin_rounds else ''}; last increments:")
    else:
        head = (f"the fixed-stress split did not converge in {failure.max_iterations} "
                f"iterations at t = {failure.t:g} (step {w.K + 1}); last increments:")
    # a step at the threshold of an opening or a contact change can keep the
    # split cycling where half the step passes (docs/theory.md, "Flow in a
    # fault": the split through an opening)
    return (head + "".join(w.log[-3:]) + " " + failure.advice
            + (", time.retry = 4 (a failed step again with half its dt, up to 4 times)"
               if failure.propose_retry else ""))


@dataclasses.dataclass
class AndersonScales:
    """The scales Anderson's norm weighs a window's blocks by: the owned
    entries of a pressure and of u, and the largest p (a fine step's) and u
    so far, the scales of the stopping test."""
    p_owned: int
    u_owned: int
    p_size: float
    u_size: float


def accelerate_window(w, comm, depth, scales):
    """Anderson's method from here on in window w (anderson.py), on its state
    (p^1, ..., p^q, u), the window's q pressures weighing as one field."""
    p_size = math.sqrt(w.q) * scales.p_size
    w.anderson = AndersonAcceleration(comm, depth, [scales.p_owned] * w.q + [scales.u_owned],
                                      [1 / p_size if p_size > 0 else 1.0] * w.q
                                      + [1 / scales.u_size if scales.u_size > 0 else 1.0])
    w.accelerated = True


def mix_iterates(w):
    """The iterate the next flow pass reads with Anderson's method: the
    combination of w's last map values (p^{n+1}, u^{n+1})."""
    x = w.anderson.next(w.p_old[1:] + [w.u_old], w.p_new[1:] + [w.u_new])
    w.p_old = [w.p_old[0]] + x[:w.q]
    w.u_old = x[w.q]


def window_name(w, t):
    """"step K (t = t)": window w in a message."""
    return f"step {w.K + 1} (t = {t:g})"


def stagnation_note(w, t, left):
    """The log's line where coupling.acceleration = "auto" hands window w (at
    t) to Anderson's method, `left` iterations left."""
    return (f"{window_name(w, t)}: the split contracts by {w.increments[-1] / w.increments[-2]:g} per "
            f"iteration, too slowly for the {left} iterations left; Anderson acceleration from iteration "
            f"{len(w.increments) + 1}")


def fault_reference(w, m):
    """The reference of the conduit faults' fixed-stress term at fine step m,
    p_f^{n,m} - p_f^{n,m-1} + p_f^{n+1,m-1}: the fault's (S + L)(p_f^{n+1,m}
    - p_f^{n+1,m-1}) = L (p_f^{n,m} - p_f^{n,m-1}) + ... as the rock's eq.
    4.17."""
    if m == 1:  # p_f^{n,0} = p_f^{n+1,0}: the window's start
        return w.fault_old[1]
    return w.fault_old[m] - w.fault_old[m - 1] + w.fault_new[m - 1]


class WindowHistory:
    """The converged state at t_K and, for BDF2, what the windows before
    left: the pressure one fine step and the displacement one window before
    t_K, the displacement path's value one fine step before t_K and the
    previous window's first fine step. From them, a window's time
    derivative, its displacement path and its fine steps' time history."""

    def __init__(self, scheme, grid):
        self.scheme, self.grid = scheme, grid  # a retry refines the grid
        self.p_K = self.u_K = None
        self.p_before = self.u_before = self.u_path_before = None
        self.j_before = 0

    def start(self, flow, u, j_previous):
        """The state at the start (t = 0 or a restart's window): p_K and the
        BDF2 values from `flow` (a restart restored them), u_K = u, and the
        first fine step of the window before."""
        self.p_K = flow.pressure.x.array.copy()
        self.u_K = u.copy()
        self.p_before = flow.p_before.x.array.copy()
        self.u_before = flow.u_before.x.array.copy()
        self.u_path_before = flow.u_path_before.x.array.copy()
        self.j_before = j_previous

    def t(self, w, m):
        """Fine time m of window w (t_K + m dt for a constant step)."""
        return self.grid.t[w.j + m]

    def derivative(self, j, q):
        """The time derivative of a window's fine steps (j the first, q of
        them): with q > 1 the fine steps share one matrix, so BDF2 needs the
        step before the window to equal the window's fine step; otherwise
        (the first window, a halved one) backward Euler, which keeps the
        global error second order."""
        dt, previous = self.grid.dt[j], self.grid.dt[j - 1] if j > 0 else 0.0
        if q > 1 and previous != dt:
            return TimeDerivative()
        return time_derivative(self.scheme, dt, previous)

    def path(self, w, u, m):
        """The displacement of window w at its fine time m along the window's
        path from u_K to u (cpp/coupling/window.cpp): backward Euler, the
        paper's straight line; BDF2, the quadratic through u_{K-1}, u_K, u
          Q(t_K + s) = u_K + s D1 + s (s - H) D2,  D1 = (u - u_K)/H,
          D2 = ((u - u_K)/H - (u_K - u_{K-1})/H1) / (H + H1),
        but in the first window u takes its end value at the first fine step
        and, with q > 1, the second window keeps the straight line."""
        bdf2 = self.scheme == TimeScheme.bdf2
        if bdf2 and w.K == 0:
            return self.u_K if m == 0 else u
        H, s = self.t(w, w.q) - self.t(w, 0), self.t(w, m) - self.t(w, 0)
        D1 = (u - self.u_K) / H
        if not (bdf2 and (w.q == 1 or w.K > 1)):
            return self.u_K + s * D1
        H1 = self.t(w, 0) - self.grid.t[self.j_before]
        D2 = (D1 - (self.u_K - self.u_before) / H1) / (H + H1)
        return self.u_K + s * D1 + s * (s - H) * D2

    def set_time_history(self, flow, w, m, p, u):
        """The time history of fine step m of `flow` from p[0..m-1] and the
        window's displacement u: backward Euler reads p[m-1] and u_K (the
        paper's scheme); BDF2 differentiates the fluid content at the fine
        times with the window's derivative, p from its fine steps and u along
        the window's path:
          p* = (c1 p[m-1] - c2 p[m-2]) / c0,  u_window = u - q (Q(t_m) - Q*),
        the values one fine step before t_K being the previous window's."""
        if self.scheme != TimeScheme.bdf2:
            flow.p_previous.x.array[:] = p[m - 1]
            return
        flow.p_previous.x.array[:] = self.previous(w, p, m)
        Q_star = history_value(w.derivative, self.path(w, u, m - 1),
                               self.path(w, u, m - 2) if m >= 2 else self.u_path_before)
        flow.u_window.x.array[:] = u - w.q * (self.path(w, u, m) - Q_star)

    def previous(self, w, p, m):
        """The history value of the iterates p[0..m-1] before fine step m."""
        return history_value(w.derivative, p[m - 1], p[m - 2] if m >= 2 else self.p_before)

    def accept(self, w, flow):
        """The accepted window w's end is the next window's start; `flow`
        keeps the BDF2 values for a checkpoint."""
        self.p_before = w.p_new[w.q - 1]  # p_K itself for q = 1
        self.u_path_before = self.path(w, w.u_new, w.q - 1)
        self.u_before = self.u_K
        self.j_before = w.j
        flow.p_before.x.array[:] = self.p_before
        flow.u_before.x.array[:] = self.u_before
        flow.u_path_before.x.array[:] = self.u_path_before
        self.p_K, self.u_K = w.p_new[w.q], w.u_new
