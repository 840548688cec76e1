"""coupling.q = "auto" (issue 25): each multirate window's q from the
predicted change of the displacement. On the fracture scene (mesh.refine =
1, dt = 12 h: the contact set grows over most of the run) the pressure error
at every flow step, against a run on the same mesh with a 16 times shorter
BDF2 monolithic step (the time error, relative to the pressure change,
in l2 over the flow steps and the largest), is within 1 % of the
single-rate split's with the same flow step, backward Euler and BDF2; no
window of q > 1 spans a change of the contact set, node by node (a
window in which it changed is computed again with q = 1); windows of q > 1 are taken and a
smaller tolerance takes smaller ones. The rule itself on synthetic grids:
stops, rate, limit and a change of dt end a window. The prototype gives
the C++ windows, iterations and fields."""
import numpy as np

from support import check, max_difference, run_track, scene, set_changes, summary, windows
from python_prototype.time.window_control import window_limit, window_steps
from python_prototype.output.time_series import Fields
from python_prototype.time.time_grid import TimeGrid, halve_steps

DT = 43200.0
BASE = ["mesh.refine=1", f"time.dt={DT}"]
AUTO = ["coupling.scheme=multirate", "coupling.q=auto"]


def pressure_error(out, reference):
    """The pressure error over the flow steps t, relative to the
    reference's change p_ref(t) - p(0): in l2 over the steps (every step
    counts) and the largest (the first steps', where the change is small,
    dominate it); and the number of steps."""
    run, ref = Fields(out), Fields(reference)
    p0 = ref.at("pressure", 0.0)
    errors, changes = [], []
    for t in run.times("pressure")[1:]:
        k = min(ref.times("pressure"), key=lambda s: abs(s - t))
        assert abs(k - t) <= 1e-9 * t, f"reference not written at t = {t:g}"
        y = ref.at("pressure", k)
        errors.append(np.linalg.norm(run.at("pressure", t) - y))
        changes.append(np.linalg.norm(y - p0))
    errors, changes = np.array(errors), np.array(changes)
    return np.linalg.norm(errors) / np.linalg.norm(changes), errors.max() / changes.max(), len(errors)


# The rule itself (the prototype's window_control, which the C++ mirrors:
# the prototype = C++ check below): the stops, the rate, the limit, a
# change of dt (a retry's halved steps) end a window; the limit's update.
grid = TimeGrid([0.1 * k for k in range(11)], [0.1] * 10)
stops = [0.5, 1.0]
check(window_steps(grid, 0, 16, 0.0, 1e-2, stops) == 5 and window_steps(grid, 5, 16, 0.0, 1e-2, stops) == 5,
      "window_control: a window ends on every stop")
check(window_steps(grid, 0, 16, 1.0, 0.25, stops) == 2 and window_steps(grid, 0, 16, 1.0, 0.05, stops) == 1
      and window_steps(grid, 0, 3, 0.0, 1e-2, stops) == 3, "window_control: q dt rate <= tolerance, q <= limit, q >= 1")
halve_steps(grid, 1, 2)
check(window_steps(grid, 0, 16, 0.0, 1e-2, stops) == 1 and window_steps(grid, 1, 16, 0.0, 1e-2, stops) == 4
      and window_steps(grid, 5, 16, 0.0, 1e-2, stops) == 2, "window_control: a window's fine steps share one dt")
check((window_limit(4, 16, True), window_limit(4, 16, False), window_limit(16, 16, False)) == (1, 8, 16),
      "window_control: the limit is 1 after a change of the contact set, else doubles up to q_max")

reference, _ = run_track("C++", scene("fracture"), *BASE, f"time.dt={DT / 16}", "coupling.scheme=monolithic",
                         "time.scheme=bdf2", f"output.every={DT}")
for time_scheme in ("backward-euler", "bdf2"):
    scheme = [f"time.scheme={time_scheme}"]
    single, _ = run_track("C++", scene("fracture"), *BASE, *scheme, "coupling.scheme=fixed-stress")
    auto, _ = run_track("C++", scene("fracture"), *BASE, *scheme, *AUTO)
    s = summary(auto)
    *e_single, n_single = pressure_error(single, reference)
    *e_auto, n_auto = pressure_error(auto, reference)
    check(s["fine_steps"] == summary(single)["fine_steps"] == n_auto == n_single,
          f"{time_scheme}: q = auto takes the single-rate flow steps ({s['fine_steps']})")
    for measure, a, b in zip(("l2 over the steps", "largest"), e_auto, e_single):
        check(a <= 1.01 * b,
              f"{time_scheme}: pressure error of q = auto within 1 % of single rate's ({measure}): {a:.4e} "
              f"against {b:.4e} ({a / b:.4f}) in {s['steps']} windows (mean q {s['window_steps']['mean_q']:.2f}, "
              f"largest {s['window_steps']['largest_q']}) against {summary(single)['steps']}")
    check(s["window_steps"]["largest_q"] > 1 and s["window_steps"]["q_rejections"] > 0,
          f"{time_scheme}: windows of q > 1 taken ({s['window_steps']['largest_q']}), "
          f"{s['window_steps']['q_rejections']} computed again with q = 1 for a change of the contact set")
    history = windows(auto, DT)
    check(sum(q for q, _ in history) == s["fine_steps"] and len(history) == s["steps"],
          f"{time_scheme}: the windows' q add up to the flow steps")
    spans = [k for k in range(1, len(history)) if history[k][0] > 1 and history[k][1] != history[k - 1][1]]
    check(not spans and history[0][0] == 1,
          f"{time_scheme}: no window of q > 1 spans a change of the active contact nodes "
          f"(q per window: {[q for q, _ in history]})")
    changed = set_changes(auto, DT, history)
    check(not changed, f"{time_scheme}: no window of q > 1 spans a change of the contact set, node by node "
          f"(windows that do: {changed})")

tight, _ = run_track("C++", scene("fracture"), *BASE, *AUTO, "coupling.q_tolerance=1e-3")
loose = summary(auto)
check(summary(tight)["window_steps"]["mean_q"] < loose["window_steps"]["mean_q"],
      f"q_tolerance 1e-3 takes smaller windows than 1e-2 (mean q {summary(tight)['window_steps']['mean_q']:.2f} "
      f"against {loose['window_steps']['mean_q']:.2f})")

# Without contact (Terzaghi: the settlement slows down) the windows grow,
# at most doubling, up to q_max, and end on every output time.
terzaghi, _ = run_track("C++", scene("terzaghi"), *AUTO, "coupling.q_max=8", "output.every=0.25")
history = [q for q, _ in windows(terzaghi, 0.01)]
ends = np.cumsum(history) * 0.01
check(history[0] == 1 and max(history) == 8 and all(b <= 2 * a for a, b in zip(history, history[1:])),
      f"Terzaghi: windows from q = 1, at most doubling, up to q_max = 8: {history}")
check(all(np.isclose(ends, t, rtol=0, atol=1e-9).any() for t in (0.25, 0.5, 0.75, 1.0)),
      "Terzaghi: a window ends on every output time")

# The prototype: the same windows, iterations and fields.
cpp, _ = run_track("C++", scene("fracture"), *AUTO, "time.scheme=bdf2")
prototype, _ = run_track("prototype", scene("fracture"), *AUTO, "time.scheme=bdf2")
a, b = summary(cpp), summary(prototype)
check(all(a[k] == b[k] for k in ("steps", "fine_steps", "coupling_iterations", "window_steps")),
      f"prototype = C++: {a['steps']} windows, {a['coupling_iterations']} iterations, {a['window_steps']}")
difference = max_difference(cpp, prototype, ("pressure", "displacement"))
check(max(difference.values()) <= 1e-8, f"prototype = C++ fields: {difference}")
