"""The scheme of a scene with one solve per step: the monolithic system, or
a single physics (flow only, mechanics only); cpp/coupling/single_solve.cpp.
It drives any step through the step interface (steps/step.py)."""
import math

from ..assembly.parameters import set_time_step
from ..contact.contact_state import ActiveSet
from .contraction import relative
from .coupling import CouplingError, IterationRecord
from ..solvers.solver import SolverError
from ..time.time_grid import FailedStep, retry_step
from ..time.time_scheme import time_derivative
from ..time.step_control import StepSolution


def _error_accepted(step, k, active_before, run):
    """time.adaptive: whether the step's error estimate accepts step k (the
    control then plans the next steps, otherwise the step's, shorter; a step
    in which the active contact set changed from `active_before` is accepted
    unestimated)."""
    if run.control is None:
        return True
    smooth = step.same_contact_set(active_before)
    accepted, message = run.control.judge(
        StepSolution(k, step.pressure_values(), step.displacement_values(), smooth), run.grid, run.report.adaptive,
        run.state.adaptive)
    if not accepted:
        run.observer.retry(message)
    return accepted


def _begin_step(problem, step, grid, k):
    """The step's time derivative; with a new dt (time.growth, a retry,
    time.adaptive) the step rebuilds what depends on it."""
    d = time_derivative(problem.scene.time_scheme, grid.dt[k - 1], grid.dt[k - 2] if k >= 2 else 0.0)
    if set_time_step(problem.forms, d.effective_step(grid.dt[k - 1])):
        step.time_step_changed()
    return d


def _record_solves(step, k, t, run):
    """iterations.csv: a row per solve of step k's last advance (also of one
    that failed), its changes relative to the largest p, u and p_f of the
    run so far, as in the split's stopping test, and p_f's change to the
    solve before's."""
    c, fault_previous = run.state, math.nan
    for i, s in enumerate(step.solves()):
        c.p_size, c.u_size = _larger(c.p_size, s.p), _larger(c.u_size, s.u)
        c.fault_p_size = _larger(c.fault_p_size, s.fault_p)
        fault_ratio = s.fault_dp / fault_previous if i > 0 and fault_previous > 0 else math.nan
        run.observer.record(IterationRecord(k, t, i + 1, math.nan, math.nan, math.nan, relative(s.dp, c.p_size),
                                            relative(s.du, c.u_size), s.active_nodes,
                                            relative(s.fault_dp, c.fault_p_size), fault_ratio, s.newton_steps))
        fault_previous = s.fault_dp


def _larger(size, value):
    """The larger of a size and a value; the size where the value is NaN."""
    return value if value > size else size


def run_single_solve(problem, step, run):
    """Runs the scene from the end of step run.report.windows (0, or a
    restart's) to its end time, one solve of `step` per step of run.grid (a
    CouplingRun, coupling.py). A step whose solve fails is retried with
    halved steps (time.retry), and so is one whose solution conserves too
    little (step.unbalanced); otherwise the SolverError, or a CouplingError
    naming the step, ends the run. With
    run.control (time.adaptive) a step whose error estimate is too large is
    tried again, shorter, and each accepted one plans the next."""
    attempts = [0]  # retries of the current step (time.retry)
    k = run.report.windows + 1
    while k <= run.grid.steps():
        t = run.grid.t[k]
        d = _begin_step(problem, step, run.grid, k)
        start = step.state()
        step.begin_step()
        active_before = step.active_contact_set() if run.control else ActiveSet()
        try:
            step.advance(t, d)
            failure, error = step.unbalanced(t), None  # a solution that conserves too little
        except SolverError as e:
            failure, error = str(e), e
        _record_solves(step, k, t, run)
        if failure:
            message = retry_step(problem.scene, FailedStep(k, failure, k - 1, 1), attempts, run.report, run.grid)
            if message is None:
                raise error if error is not None else CouplingError(f"step {k} (t = {t:g}): {failure}")
            run.observer.retry(message)
            step.restore(start)
            continue  # the same step again, halved
        if not _error_accepted(step, k, active_before, run):
            step.restore(start)
            continue  # the same step again, shorter
        attempts[0] = 0
        step.keep_history(start)
        step.accept(t)
        run.observer.flow_state(t)
        run.observer.mechanics_state(t, k, step.iterations())
        run.report.windows = k
        run.report.fine_steps = k
        run.state.window_q = 1  # a window of one fine step, for the split that takes over (BDF2's history)
        k += 1
        if run.observer.stop():
            break
