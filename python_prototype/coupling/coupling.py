"""What every coupling scheme (the fixed-stress split, the single solve per
step) reports and whom it tells: the report of summary.json and
checkpoints, the controllers' state, and the observer that writes, prints
and stops (cpp/coupling/coupling.h)."""
import math
from dataclasses import dataclass, field, fields
from typing import Callable, Optional

from ..time.step_control import AdaptiveReport, AdaptiveState


class CouplingError(Exception):
    """The split did not converge within coupling.max_iterations, or a
    step's converged state fails what it must conserve (Step.unbalanced)."""


@dataclass
class CouplingReport:
    """What a run's coupling did, step by step: the counts and contraction
    measures of summary.json (paper Theorems 1 and 2). Written by the
    schemes, read by the summary; the schemes decide nothing from it but
    where the run stands (windows, fine_steps)."""
    windows: int = 0                   # mechanics (coarse) steps
    fine_steps: int = 0                # flow (fine) steps: windows times q, or their sum with q = "auto"
    coupling_iterations: int = 0
    max_iterations_per_step: int = 0
    max_contraction_ratio: float = 0.0
    mean_contraction_ratio: float = 0.0
    ratios: int = 0                    # ratios held against gamma (resolved)
    bound_violations: int = 0          # resolved ratios above gamma
    unresolved_ratios: int = 0         # ratios at round-off level, logged only
    max_coupled_residual: float = 0.0  # relative, of each converged state
    retries: int = 0                   # failed steps retried with halved steps (time.retry)
    adaptive: AdaptiveReport = field(default_factory=AdaptiveReport)  # time.adaptive (time/step_control.py)
    max_window_q: int = 0              # coupling.q = "auto": the largest q taken
    q_rejections: int = 0              # ... windows tried again with q = 1: the contact set changed in them
    accelerated_windows: int = 0       # coupling.acceleration = "auto": windows handed to Anderson where they stagnate
    pinned_windows: int = 0            # windows accepted with pins (pins.py)
    fallback_steps: int = 0            # coupling.fallback: steps the monolithic scheme solved where the split failed


@dataclass
class ControllerState:
    """The memory the schemes' controllers carry from window to window (and
    through a checkpoint): not reported, read back to decide."""
    # The sum of the resolved contraction ratios (their mean at the end) and
    # the scales of the stopping test: the largest p and u so far.
    ratio_sum: float = 0.0
    p_size: float = 0.0
    u_size: float = 0.0
    fault_p_size: float = 0.0  # the largest l2 norm of the conduit faults' p_f so far
    # time.adaptive: the PI controller's memory (time/step_control.py).
    adaptive: AdaptiveState = field(default_factory=AdaptiveState)
    # The last window's q (1 after a single solve's step) and, with
    # coupling.q = "auto" (window_control.py), the largest q the next may
    # take (1 after a change of the contact set, then doubling).
    window_q: int = 0
    q_limit: int = 1


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
    # The conduit faults' p_f increment (relative, as dp_norm) and its ratio
    # to the last iteration's (NaN without conduit faults).
    fault_dp_norm: float = math.nan
    fault_ratio: float = math.nan
    # The Newton steps of the iteration's contact solve (0 without contact).
    newton_steps: int = 0


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
    # Told that the split changed its iteration in a window (Anderson's
    # taking over where it stagnated).
    note: Optional[Callable[[str], None]] = None
    # Told after each coupling iteration (window, iteration, increments dp
    # and du): the progress of a long window.
    iteration: Optional[Callable[[int, int, float, float], None]] = None
    # Told what each coupling iteration measured (iterations.csv).
    record: Optional[Callable[[IterationRecord], None]] = None


@dataclass
class CouplingRun:
    """The run a scheme drives: the time grid it steps on (time.retry and
    time.adaptive rewrite it), time.adaptive's control (None without), the
    observer it tells, the report it fills and the controllers' state. Grid,
    report and state are what a checkpoint keeps of it."""
    grid: object  # TimeGrid
    control: object  # StepControl (time/step_control.py), or None
    observer: WindowObserver
    report: CouplingReport
    state: ControllerState


# The fields of the report and of the controllers' state that a checkpoint
# keeps, in the order of the C++.
CHECKPOINTED = ("windows", "coupling_iterations", "max_iterations_per_step", "max_contraction_ratio", "ratios",
                "bound_violations", "unresolved_ratios", "max_coupled_residual", "ratio_sum", "p_size", "u_size",
                "fault_p_size", "retries", "rejected_steps", "forced_steps", "max_error_estimate", "error_estimate",
                "p_largest", "u_largest", "contact_breaks", "smooth_states", "fine_steps", "window_q", "q_limit",
                "max_window_q", "q_rejections", "accelerated_windows", "fallback_steps", "pinned_windows")


def for_each_checkpointed(report, state, f):
    """Calls f(holder, name) for each field of the report and the
    controllers' state that a checkpoint keeps, `holder` the one of the two
    that has it (time.adaptive's fields: report.adaptive and state.adaptive):
    the one list that checkpoints and restarts read (C++ hands f the field
    itself; f reads or sets getattr(holder, name) here)."""
    holders = {}
    for holder in (report, state, report.adaptive, state.adaptive):
        holders.update((member.name, holder) for member in fields(holder))
    for name in CHECKPOINTED:
        f(holders[name], name)
