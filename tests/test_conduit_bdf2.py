"""BDF2 for a conduit fault's storage (issue 53; docs/theory.md, "Time
schemes"), in the single-rate schemes and without mechanics (a multirate
scheme is refused: test_bad_scenes). scenes/conduit_transient.toml against
a run at dt = 1e-6 s: p_f converges at order 1 (backward Euler, 0.9-1.1)
and at least 1.8 (BDF2), BDF2 at least 30 times more accurate at the
finest step, every step balanced, prototype = C++ (1e-12). Injection into
fault_reactivation's frictional conduit (seven days, opening from day 6)
under BDF2: split and monolithic converge, the fault opens by the well,
balanced (1e-8), split = monolithic (1e-9, 1e-8), prototype = C++ (1e-9).
Killed and restarted, the transient ends equal (1e-12) on both tracks: the
checkpoint keeps the previous step's p_f and apertures. Numbers:
docs/verification.md."""
import numpy as np
from support import (check, fault_fields, killed_and_restarted, max_difference, run_track, scene, summary)

TRANSIENT = scene("conduit_transient")
STEPS = (1.0e-4, 5.0e-5, 2.5e-5, 1.25e-5)
P0 = 1.0e6  # the initial pressure


def fault_pressure(track, time_scheme, dt):
    out, _ = run_track(track, TRANSIENT, f'time.scheme="{time_scheme}"', f"time.dt={dt}", "output.every=1e-3")
    _, _, series = fault_fields(out, ("pressure",))
    return series[-1]["pressure"][:, 0]


reference = fault_pressure("C++", "bdf2", 1.0e-6)
errors = {}
for time_scheme in ("backward-euler", "bdf2"):
    errors[time_scheme] = [np.linalg.norm(fault_pressure("C++", time_scheme, dt) - reference)
                           / np.linalg.norm(reference - P0) for dt in STEPS]
orders = {k: np.log2(np.array(e[:-1]) / np.array(e[1:])) for k, e in errors.items()}
check(np.all((orders["backward-euler"] >= 0.9) & (orders["backward-euler"] <= 1.1)),
      f"backward Euler: first order in time on the conduit: {np.round(orders['backward-euler'], 2)}")
check(np.all(orders["bdf2"] >= 1.8), f"BDF2: second order in time on the conduit: {np.round(orders['bdf2'], 2)} "
      f"(errors {['%.2e' % e for e in errors['bdf2']]})")
check(errors["backward-euler"][-1] >= 30 * errors["bdf2"][-1],
      f"BDF2 {errors['backward-euler'][-1] / errors['bdf2'][-1]:.0f} times more accurate at dt = {STEPS[-1]} (30)")
cpp, prototype = fault_pressure("C++", "bdf2", STEPS[2]), fault_pressure("prototype", "bdf2", STEPS[2])
d = np.abs(prototype - cpp).max() / np.abs(cpp - P0).max()
check(d <= 1e-12, f"the prototype's BDF2 conduit equals the C++ one: {d:.1e} (1e-12)")

REACTIVATION = scene("fault_reactivation")
INJECTION = ("well.injector.position=[0.0, 0.0]", 'well.injector.fault="fault"', "well.injector.rate=5.0e-4",
             "fault.fault.pore_pressure_load=false", 'fault.fault.flow="conduit"',
             "fault.fault.residual_aperture=1.0e-4", "time.end=604800.0", "coupling.tolerance=1e-11",
             "coupling.max_iterations=400", 'time.scheme="bdf2"')
FIELDS = ["displacement", "pressure"]


def check_opened(out, label):
    """Converged, open by the well at the end, the volumes balanced."""
    s = summary(out)
    _, _, series = fault_fields(out, names=("state",))
    opened = int(np.sum(series[-1]["state"][:, 0] == 0))
    v = s["fault_volumes"]["fault"]
    balance = abs(v["injected"] + v["exchanged"] - v["stored"] - v["outflow"]) / v["injected"]
    check(s["converged"] is True and s["steps"] == 7 and opened >= 1 and balance <= 1e-8,
          f"{label}: 7 steps converged under BDF2, {opened} pairs open, volumes balanced to {balance:.1e} (1e-8)")


split, _ = run_track("C++", REACTIVATION, *INJECTION)
check_opened(split, "C++ split")
monolithic, _ = run_track("C++", REACTIVATION, *INJECTION, 'coupling.scheme="monolithic"')
check_opened(monolithic, "C++ monolithic")
d = max_difference(split, monolithic, FIELDS)
check(d["displacement"] <= 1e-9 and d["pressure"] <= 1e-8,
      f"C++: under BDF2 the split equals the monolithic solve through the opening: {d} (1e-9, 1e-8)")
prototype_split, _ = run_track("prototype", REACTIVATION, *INJECTION)
check_opened(prototype_split, "prototype split")
d = max_difference(split, prototype_split, FIELDS)
check(max(d.values()) <= 1e-9, f"the prototype's split equals the C++ split under BDF2: {d} (1e-9)")
# The restart on the transient, whose p_f is all storage (the injection's
# fault stores 1e-5 of what it takes in: its p_f^{n-1} moves nothing).
RESTART = ('time.scheme="bdf2"', "time.dt=2.5e-6", "output.every=2.5e-4")
for track in ("C++", "prototype"):
    uninterrupted, _ = run_track(track, TRANSIENT, *RESTART)
    restarted, step = killed_and_restarted(track, TRANSIENT, 5, *RESTART)
    a, b = (fault_fields(out, ("pressure",))[2][-1]["pressure"] for out in (uninterrupted, restarted))
    d = np.abs(a - b).max() / np.abs(a - P0).max()
    check(4 <= step < 400 and d <= 1e-12,
          f"{track}: the transient killed after step 5, restarted from step {step} under BDF2: p_f {d:.1e} (1e-12)")
