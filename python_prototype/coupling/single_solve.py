"""The scheme of a scene with one solve per step: the monolithic system, or
a single physics (flow only, mechanics only); cpp/coupling/single_solve.cpp."""
from ..assembly.parameters import set_time_step
from ..contact.contact import ActiveSet, same_active_set
from ..solvers.solver import SolverError
from ..steps.time_grid import retry_step
from ..steps.time_scheme import history_value, time_derivative


def step_start(flow, mechanics, monolithic):
    """The unknowns at the start of a step, to go back to when it is retried,
    and the accumulation's state (pressure; and displacement of the
    monolithic step), BDF2's memory once the step is accepted."""
    history = (None, None)
    if flow:
        history = (flow.pressure.x.array.copy(), None)
    if monolithic:
        history = (monolithic.pressure.x.array.copy(), monolithic.u.x.array.copy())
    return (flow.unknowns().copy() if flow else None, mechanics.u.x.array.copy() if mechanics else None,
            monolithic.unknowns().copy() if monolithic else None) + history


def keep_history(start, flow, monolithic):
    """An accepted step's start becomes the state one step before the next."""
    p, u = start[3:]
    if flow:
        flow.p_before.x.array[:] = p
    if monolithic:
        monolithic.p_before.x.array[:] = p
        monolithic.u_before.x.array[:] = u


def go_back(start, flow, mechanics, monolithic):
    flow_unknowns, displacement, monolithic_unknowns = start[:3]
    if flow:
        flow.set_unknowns(flow_unknowns)
    if mechanics:
        mechanics.u.x.array[:] = displacement
    if monolithic:
        monolithic.set_unknowns(monolithic_unknowns)


def solve_step(t, d, flow, mechanics, monolithic):
    """The solves of step t: the flow from the last step's pressure (BDF2: its
    history value, time_scheme.py), then the mechanics with the new one (a
    single physics has one of them)."""
    if monolithic:
        monolithic.solve(t, d)
    if flow:
        flow.p_previous.x.array[:] = history_value(d, flow.pressure.x.array, flow.p_before.x.array)
        flow.solve(t)
    if mechanics:
        mechanics.solve(t)


def active_contact_set(mechanics, monolithic):
    """The contact active set of the step's displacement (empty without contact)."""
    step = mechanics or monolithic
    return step.active_contact_set() if step else ActiveSet()


def same_contact_set(mechanics, monolithic, before):
    """Whether the step's displacement has the contact active set `before`
    (collective; true without mechanics)."""
    step = mechanics or monolithic
    return same_active_set(step.active_contact_set(), before, step.u.function_space.mesh.comm) if step else True


def error_accepted(control, grid, k, flow, mechanics, monolithic, active_before, report, observer):
    """time.adaptive: whether the step's error estimate accepts it (the
    control then plans the next steps, otherwise the step's, shorter; a step
    in which the active contact set changed from `active_before` is accepted
    unestimated)."""
    if control is None:
        return True
    smooth = same_contact_set(mechanics, monolithic, active_before)
    p = (flow or monolithic).pressure.x.array if (flow or monolithic) else None
    u = (mechanics or monolithic).u.x.array if (mechanics or monolithic) else None
    message = control.judge(grid, k, p, u, smooth, report)
    if message is None:
        return True
    observer.retry(message)
    return False


def run_single_solve(scene, F, flow, mechanics, monolithic, observer, report, grid, control):
    """Runs the scene from the end of step report.windows (0, or a restart's)
    to its end time, one solve per step: the monolithic step, or the one step
    the scene has (the others are None). A step whose solve fails is retried
    with halved steps (time.retry); otherwise the SolverError ends the run.
    With `control` (time.adaptive) a step whose error estimate is too large
    is tried again, shorter, and each accepted one plans the next."""
    attempts = [0]  # retries of the current step (time.retry)
    k = report.windows + 1
    while k <= grid.steps():
        t = grid.t[k]
        d = time_derivative(scene.time_scheme, grid.dt[k - 1], grid.dt[k - 2] if k >= 2 else 0.0)
        if set_time_step(F, d.effective_step(grid.dt[k - 1])):
            if monolithic:
                monolithic.time_step_changed()
            if flow:
                flow.time_step_changed()
        start = step_start(flow, mechanics, monolithic)
        active_before = active_contact_set(mechanics, monolithic) if control else ActiveSet()
        try:
            solve_step(t, d, flow, mechanics, monolithic)
        except SolverError as e:
            message = retry_step(scene, str(e), k, attempts, grid, k - 1, 1, report)
            if message is None:
                raise
            observer.retry(message)
            go_back(start, flow, mechanics, monolithic)
            continue  # the same step again, halved
        if not error_accepted(control, grid, k, flow, mechanics, monolithic, active_before, report, observer):
            go_back(start, flow, mechanics, monolithic)
            continue  # the same step again, shorter
        attempts[0] = 0
        keep_history(start, flow, monolithic)
        if flow or monolithic:
            observer.flow_state(t)
        observer.mechanics_state(t, k, 1)
        report.windows = k
        report.fine_steps = k
        k += 1
        if observer.stop():
            break
