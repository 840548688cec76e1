"""coupling.q = "auto": the number q of flow (fine) steps of each multirate
window, chosen before the window from the predicted change of the
mechanics over it (docs/theory.md, "Multirate with q = auto");
cpp/time/window_control.{h,cpp}."""
import bisect
import math


def window_steps(grid, j, limit, rate, tolerance, stops):
    """The q of the window that starts at fine step j of `grid`: the largest
    whose predicted relative change of u, q dt * rate (rate = ||u_K -
    u_{K-1}|| / (u_size H_1)), stays within `tolerance`, at most `limit`,
    over fine steps of one dt and not past the next of `stops`; at least 1."""
    dt, slack = grid.dt[j], 1e-9 * grid.t[-1]
    next_stop = stops[bisect.bisect_right(stops, grid.t[j] + slack)]
    if rate > 0:
        limit = min(limit, int(min(1e9, math.floor(tolerance / (rate * dt)))))
    q = 1
    while q < limit and j + q < grid.steps() and grid.dt[j + q] == dt and grid.t[j + q] < next_stop - slack:
        q += 1
    return q


def window_limit(q, q_max, contact_changed):
    """The limit of the next window's q after a window of q fine steps: 1 if
    the contact set changed in it, else twice q, at most q_max."""
    return 1 if contact_changed else min(q_max, 2 * q)
