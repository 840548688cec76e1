"""The times of a run and the step of each (cpp/time/time_grid.h): kept exactly
(dt from the scene, grown by time.growth, or planned by time.adaptive) so
that a constant step is recognised as unchanged; a failed step retried with
time.retry has its fine steps halved (dt/2 is exact in binary floating
point); an adaptive run plans the steps after each accepted one again
(step_control.py); a checkpoint keeps the grid."""
import math
from dataclasses import dataclass


class TimeGrid:
    def __init__(self, t, dt):
        self.t = list(t)    # N + 1 times
        self.dt = list(dt)  # N steps

    def steps(self):
        return len(self.dt)


def time_grid(scene):
    """The scene's times with their steps."""
    if scene.adaptive:
        grid = TimeGrid([0.0], [])
        plan_steps(grid, 0, scene.dt, scene.stops())
        return grid
    t = scene.times()
    return TimeGrid(t, [scene.dt if scene.growth == 1.0 else t[k + 1] - t[k] for k in range(len(t) - 1)])


def plan_steps(grid, k, h, stops):
    """Replaces the steps after t_k by steps of about h that land on every
    stop after t_k (Scene.stops): n = ceil((stop - t) / h) equal steps to each."""
    del grid.t[k + 1:], grid.dt[k:]
    slack = 1e-12 * stops[-1]
    for stop in stops:
        t0 = grid.t[-1]
        if stop <= t0 + slack:
            continue
        n = max(1, math.ceil((stop - t0) / h - 1e-9))
        step = (stop - t0) / n
        grid.t += [stop if i == n else t0 + i * step for i in range(1, n + 1)]
        grid.dt += [step] * n


def halve_steps(grid, first, count):
    """Halves the steps first, ..., first + count - 1 (count more steps)."""
    t, dt = grid.t[:first + 1], grid.dt[:first]
    for k in range(first, first + count):
        half = grid.dt[k] / 2
        t += [grid.t[k] + half, grid.t[k + 1]]
        dt += [half, half]
    grid.t = t + grid.t[first + count + 1:]
    grid.dt = dt + grid.dt[first + count:]


@dataclass
class FailedStep:
    """A step that failed: its number (for the message), why, and its fine
    steps first, ..., first + count - 1 on the grid."""
    step: int
    cause: str
    first: int
    count: int


def retry_step(scene, failed, attempts, report, grid):
    """time.retry: whether the FailedStep `failed` may be tried again with
    halved steps (`attempts[0]` retries of it so far, at most scene.retry);
    if so, counts the retry in attempts[0] and report.retries (the run's),
    halves the failed fine steps of `grid` and returns the message that says
    so (else None)."""
    if attempts[0] >= scene.retry:
        return None
    attempts[0] += 1
    report.retries += 1
    halve_steps(grid, failed.first, failed.count)
    return (f"step {failed.step} failed ({failed.cause}); retry {attempts[0]} of {scene.retry} "
            f"with dt = {grid.dt[failed.first]:g}")
