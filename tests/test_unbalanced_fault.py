"""Converged means balanced (issue 50, item 3): a conduit fault whose step leaves
injected + exchanged = stored + outflow off by more than its tolerance is no
accepted step. Three runs that ended with exit 0, "converged": true and a wrong
answer before, on both tracks: a well into the frictional conduit fault of
scenes/fault_reactivation.toml with a normal permeability of 1e-30 (the fault
stored 25x what was injected), and the same fault with residual apertures of 1
m and 10 m (transmissivity 1e13 and 1e16 times the rock's: the exchange off by
2e-4 and 1.6 of the injection). Each now ends with exit 3, one line naming the
step and the fault, summary.json "failed" with "converged": false and no step
kept; and with time.retry the step is tried again on halved steps before it
fails. A balanced run (residual aperture 1e-4 m, k_n infinite) still completes,
its volumes balanced, on both tracks."""
from support import check, run_track, scene, summary

REACTIVATION = scene("fault_reactivation")
INTO_FAULT = ("well.injector.position=[0.0, 0.0]", 'well.injector.fault="fault"', "well.injector.rate=1.0e-4",
              "fault.fault.pore_pressure_load=false", 'fault.fault.flow="conduit"', "time.end=172800.0")
CASES = [("k_n = 1e-30", ("fault.fault.residual_aperture=1.0e-4", "fault.fault.normal_permeability=1.0e-30")),
         ("w_r = 1 m", ("fault.fault.residual_aperture=1.0",)),
         ("w_r = 10 m", ("fault.fault.residual_aperture=10.0",))]


def check_refused(track, label, sets):
    out, p = run_track(track, REACTIVATION, *INTO_FAULT, *sets, expect=3)
    lines = p.stderr.strip().splitlines()
    s = summary(out)
    check(len(lines) == 1 and "step 1 (t = 86400): fault.fault: its volumes do not balance" in lines[0]
          and s["status"] == "failed" and s["converged"] is False and s["steps"] == 0
          and s["fault_volumes"]["fault"]["injected"] == 0,
          f"{track}: {label}: exit 3, one line {lines[-1][:150]!r}..., summary.json failed, not converged, "
          f"no step kept")
    return out


def check_retried(track):
    """time.retry = 1: the unbalanced step is tried again on halved steps,
    which fail alike; the log says so."""
    out, p = run_track(track, REACTIVATION, *INTO_FAULT, *CASES[0][1], "time.retry=1", expect=3)
    s = summary(out)
    check(s["retries"] == 1 and "retry 1" in p.stdout + p.stderr and "do not balance" in s["failure"],
          f"{track}: with time.retry = 1 the unbalanced step is retried once ({s['retries']}), then fails")


def check_balanced(track):
    out, _ = run_track(track, REACTIVATION, *INTO_FAULT, "fault.fault.residual_aperture=1.0e-4")
    s = summary(out)
    v = s["fault_volumes"]["fault"]
    balance = abs(v["injected"] + v["exchanged"] - v["stored"] - v["outflow"]) / v["injected"]
    check(s["converged"] is True and s["steps"] == 2 and balance <= 1e-8,
          f"{track}: w_r = 1e-4 m, k_n infinite: completed, converged, the volumes balanced to {balance:.1e} (1e-8) "
          f"of the {v['injected']:.3g} m^2 injected")


for track in ("C++", "prototype"):
    for label, sets in CASES:
        check_refused(track, label, sets)
    check_retried(track)
    check_balanced(track)
