"""What every coupling scheme (the fixed-stress split, the single solve per
step) reports and whom it tells: the report of summary.json and
checkpoints, and the observer that writes, prints and stops
(cpp/coupling/coupling.h)."""
from dataclasses import dataclass
from typing import Callable, Optional


class CouplingError(Exception):
    """The split did not converge within coupling.max_iterations."""


class CouplingReport:
    """What a run's coupling did, step by step: the counts and contraction
    measures of summary.json (paper Theorems 1 and 2)."""

    def __init__(self):
        self.windows = 0                   # mechanics (coarse) steps
        self.fine_steps = 0                # flow (fine) steps: windows times q, or their sum with q = "auto"
        self.coupling_iterations = 0
        self.max_iterations_per_step = 0
        self.max_contraction_ratio = self.mean_contraction_ratio = 0.0
        self.ratios = 0                    # ratios held against gamma (resolved)
        self.bound_violations = 0          # resolved ratios above gamma
        self.unresolved_ratios = 0         # ratios at round-off level, logged only
        self.max_coupled_residual = 0.0    # relative, of each converged state
        self.retries = 0                   # failed steps retried with halved steps (time.retry)
        self.rejected_steps = 0            # time.adaptive: steps tried again, shorter, for their error estimate
        self.forced_steps = 0              # ... accepted at dt_min above the tolerance
        self.max_error_estimate = 0.0      # ... the largest of an accepted step (1: the tolerance)
        self.contact_breaks = 0            # ... steps accepted unestimated: the active contact set changed in them
        # Carried from window to window (and through a checkpoint): the sum
        # of the resolved ratios and the scales of the stopping test.
        self.ratio_sum = self.p_size = self.u_size = 0.0
        # time.adaptive: the last accepted step's error estimate (the PI
        # controller's memory) and the largest norms of pressure and displacement.
        self.error_estimate = self.p_largest = self.u_largest = 0.0
        self.smooth_states = 0  # accepted states since t = 0 or the last contact break: the predictor's reach
        # coupling.q = "auto" (window_control.py): the last window's q, the
        # largest q the next may take (1 after a change of the contact set,
        # then doubling), the largest q taken and the windows tried again
        # with q = 1 because the contact set changed in them.
        self.window_q, self.q_limit, self.max_window_q = 0, 1, 0
        self.q_rejections = 0


@dataclass
class IterationRecord:
    """What a coupling iteration measured: one row of iterations.csv."""
    step: int
    time: float
    iteration: int
    dsigma_norm: float
    ratio: float
    gamma: float
    dp_norm: float
    du_norm: float
    active_nodes: int


@dataclass
class WindowObserver:
    """Called after each converged window: flow_state(t) once per fine flow
    step (with that step's solution loaded in the FlowStep), then
    mechanics_state(t, window, iterations) once for the mechanics step."""
    flow_state: Callable[[float], None]
    mechanics_state: Callable[[float, int, int], None]
    # Asked after each accepted (and written) window: true ends the run
    # there (an interruption).
    stop: Optional[Callable[[], bool]] = None
    # Told that a window is tried again with shorter steps (a failed solve,
    # or an error estimate above time.adaptive.tolerance).
    retry: Optional[Callable[[str], None]] = None
    # Told after each coupling iteration (window, iteration, increments dp
    # and du): the progress of a long window.
    iteration: Optional[Callable[[int, int, float, float], None]] = None
    # Told what each coupling iteration measured (iterations.csv).
    record: Optional[Callable[[IterationRecord], None]] = None


# The fields of the report that a checkpoint keeps, in the order of the C++.
CHECKPOINTED = ("windows", "coupling_iterations", "max_iterations_per_step", "max_contraction_ratio", "ratios",
                "bound_violations", "unresolved_ratios", "max_coupled_residual", "ratio_sum", "p_size", "u_size",
                "retries", "rejected_steps", "forced_steps", "max_error_estimate", "error_estimate", "p_largest",
                "u_largest", "contact_breaks", "smooth_states", "fine_steps", "window_q", "q_limit", "max_window_q",
                "q_rejections")


def for_each_checkpointed(report, f):
    """Calls f(name, value) for each field of the report that a checkpoint
    keeps: the one list that checkpoints and restarts read."""
    for name in CHECKPOINTED:
        f(name, getattr(report, name))
