"""time.adaptive: the time step chosen from a local error estimate
(cpp/time/step_control.h, docs/theory.md "Adaptive steps"): Milne's
device with the Lagrange predictor through the last accepted states (linear
for backward Euler, quadratic for BDF2), the error per unit step relative to
the time reached and to the field's largest norm, a PI controller steering
the estimate to 1/2 with a band that keeps the step, rejection above 1, and
acceptance at dt_min (forced) where the estimate does not fall with h; the
predictor does not reach back across t = 0 or a step in which the active
contact set changed (a break in smoothness, accepted unestimated)."""
from dataclasses import dataclass
from typing import Optional

import numpy as np
from dolfinx import fem

from ..assembly.linear_algebra import owned_norm
from ..scene.input import TimeScheme
from .time_grid import plan_steps

# The PI controller's set point (the estimate it steers to) and the band of
# growth factors [1, BAND] that keep the step.
TARGET, BAND = 0.5, 1.1


@dataclass
class AdaptiveReport:
    """What time.adaptive did: the counts of summary.json's "adaptive"."""
    rejected_steps: int = 0          # steps tried again, shorter, for their error estimate
    forced_steps: int = 0            # accepted at dt_min above the tolerance
    max_error_estimate: float = 0.0  # the largest of an accepted step (1: the tolerance)
    contact_breaks: int = 0          # steps accepted unestimated: the active contact set changed in them


@dataclass
class AdaptiveState:
    """The PI controller's memory, carried from step to step (and through a
    checkpoint): the last accepted step's error estimate and the largest
    norms of pressure and displacement."""
    error_estimate: float = 0.0
    p_largest: float = 0.0
    u_largest: float = 0.0
    smooth_states: int = 0  # accepted states since t = 0 or the last contact break: the predictor's reach


def _milne_weight(order, t):
    """The weight of the predictor's error against the step's own: the local
    error is weight * (y_n - P); t = (t_n, t_{n-1}, ...)."""
    h, h1 = t[0] - t[1], t[1] - t[2]
    if order == 1:
        return h / (2 * h + h1)
    h2, w = t[2] - t[3], h / h1
    c0 = (1 + 2 * w) / (1 + w)
    E, C = h ** 3 * (1 + w) / (6 * w * c0), h * (h + h1) * (h + h1 + h2) / 6
    return E / (E + C)


def _local_error(y, past, order, t, V, comm):
    """||LTE|| of one field: Milne's device with the Lagrange predictor of
    degree `order` through the accepted states at t[1], ..., t[order + 1]."""
    error = np.array(y, dtype=float)
    for i in range(1, order + 2):
        weight = 1.0
        for j in range(1, order + 2):
            if j != i:
                weight *= (t[0] - t[j]) / (t[i] - t[j])
        error -= weight * past[i - 1].x.array
    return owned_norm(_milne_weight(order, t) * error, V, comm)


@dataclass
class StepSolution:
    """A step to judge: the one ending at grid.t[k] with solution (p, u)
    (either may be None); `smooth` is False when the active contact set
    changed in it."""
    k: int
    p: Optional[np.ndarray]
    u: Optional[np.ndarray]
    smooth: bool


class StepControl:
    """The error estimate and PI controller of time.adaptive, for the
    pressure in Q and the displacement in V (either may be None)."""

    def __init__(self, scene, Q, V):
        self.spec, self.stops = scene.adaptive, scene.stops()
        self.comm = (Q if Q is not None else V).mesh.comm
        self.order = 2 if scene.time_scheme == TimeScheme.bdf2 else 1  # p
        self.rejected = False  # the step being judged was rejected before
        # y_{n-1}, y_{n-2}, y_{n-3} of each field (empty for an absent one).
        self.p = [fem.Function(Q) for _ in range(3)] if Q else []
        self.u = [fem.Function(V) for _ in range(3)] if V else []

    def start(self, p, u, state):
        """The norms of the state at t = 0 (the fields' scales start there),
        into the AdaptiveState `state`."""
        state.p_largest = owned_norm(p, self.p[0].function_space, self.comm) if self.p else 0.0
        state.u_largest = owned_norm(u, self.u[0].function_space, self.comm) if self.u else 0.0

    def remember(self, p, u):
        for past, y in ((self.p, p), (self.u, u)):
            if past:
                past.insert(0, past.pop())  # y_{n-3} is overwritten
                past[0].x.array[:] = y

    def estimate(self, grid, step, state):
        """est of the step ending at t_k: the larger of the pressure's and the
        displacement's relative local error per unit step."""
        k = step.k
        t = [grid.t[k - i] for i in range(self.order + 2)]
        error = 0.0
        for past, y, name in ((self.p, step.p, "p_largest"), (self.u, step.u, "u_largest")):
            if not past:
                continue
            V = past[0].function_space
            setattr(state, name, max(getattr(state, name), owned_norm(y, V, self.comm)))
            if getattr(state, name) > 0:
                error = max(error, _local_error(y, past, self.order, t, V, self.comm) / getattr(state, name))
        return error * grid.t[k] / (grid.dt[k - 1] * self.spec.tolerance)

    def judge(self, step, grid, report, state):
        """Judges the StepSolution `step` on the TimeGrid `grid`, counting
        into the AdaptiveReport `report` and steering by the AdaptiveState
        `state`: accepted, it is remembered and the steps after t_k are
        planned again; rejected, the steps from t_{k-1} on are, shorter.
        Returns (accepted, the message that says so when rejected). A step
        that is not smooth (the active contact set changed in it) is accepted
        as it is and the predictor restarts after it."""
        k, smooth = step.k, step.smooth
        h, order = grid.dt[k - 1], self.order
        # A predictor through order + 1 accepted states after the last break.
        estimated = smooth and state.smooth_states > order
        est = self.estimate(grid, step, state) if estimated else 0.0
        if est > 1 and h > self.spec.dt_min * (1 + 1e-9):
            shorter = max(self.spec.dt_min, h * max(0.2, (TARGET / est) ** (1 / order)))
            plan_steps(grid, k - 1, shorter, self.stops)
            report.rejected_steps += 1
            self.rejected = True
            return False, (f"step {k} rejected: error estimate {est:g} > 1 (time.adaptive.tolerance); "
                           f"dt {h:g} -> {shorter:g}")
        report.forced_steps += est > 1
        report.max_error_estimate = max(report.max_error_estimate, est)
        report.contact_breaks += not smooth
        state.smooth_states = state.smooth_states + 1 if smooth else 1
        self.remember(step.p, step.u)
        factor = 1.0
        if estimated:
            before = state.error_estimate if state.error_estimate > 0 else est
            factor = BAND * (TARGET / est) ** (0.7 / order) * (before / TARGET) ** (0.4 / order) if est > 0 else 2.0
            factor = min(max(factor, 0.2), 1.0 if self.rejected else 2.0)
            if 1 <= factor <= BAND:
                factor = 1.0
            state.error_estimate = max(est, 1e-10)
        self.rejected = False
        following = min(max(h * factor, self.spec.dt_min), self.spec.dt_max)
        if following != h:
            plan_steps(grid, k, following, self.stops)
        return True, ""

    def history(self):
        """The accepted states y_{n-1}, y_{n-2}, y_{n-3} by checkpoint name."""
        return ([(f"adaptive_pressure_{i + 1}", f) for i, f in enumerate(self.p)]
                + [(f"adaptive_displacement_{i + 1}", f) for i, f in enumerate(self.u)])


def iteration_tolerance(coupling_tolerance, error_tolerance, h, t):
    """The coupling tolerance of a step of length h ending at t under
    time.adaptive (error tolerance `error_tolerance`): coupling.tolerance, at
    most a tenth of the error tolerance per unit step, tolerance h / t. The
    iteration's own error enters the error estimate multiplied by t / h:
    above that bound it would keep short steps short (a crawl at dt_min,
    docs/theory.md "Adaptive steps")."""
    return min(coupling_tolerance, 0.1 * error_tolerance * h / t)
