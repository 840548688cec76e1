"""Pins end the split's cycle at a pair's kink (issue 50, item 2: the split
converges through the opening): a well of 5e-4 m^2/s into the frictional
conduit of scenes/fault_reactivation.toml on 22.5-minute steps, to step 302,
where one pair by the well opens and closes in turn (period 4). Pinned open
with its two fault cells, the split converges and equals the monolithic
scheme's step there (coupling.pin_cycles = false, coupling.fallback =
"monolithic": the split cycles and hands the step over) to 1e-9 in the
displacement and 1e-7 in the pressure (test_friction_opening's bounds at
ten times its tolerance); 2 ranks = 1 (1e-8); prototype = C++ (1e-9), the
same line in the log on both tracks. The multirate split (q = 2) pins the
same window and converges where it cycles without pins. docs/theory.md, "Pins"."""
import re

from support import check, max_difference, run_track, scene, summary

SETS = ("well.injector.position=[0.0, 0.0]", 'well.injector.fault="fault"', "well.injector.rate=5.0e-4",
        "fault.fault.pore_pressure_load=false", 'fault.fault.flow="conduit"',
        "fault.fault.residual_aperture=1.0e-4", "coupling.tolerance=1e-10", "coupling.max_iterations=400",
        "time.dt=1350.0", "time.end=407700.0", "output.times=[405000.0, 407700.0]")
FIELDS = ["displacement", "pressure", "flux"]
PINNED = re.compile(r"^step 302 \(t = 407700\), coupling iteration \d+: the contact set cycles every 4 "
                    r"iterations; pinned open: 1 pairs, 2 fault cells$", re.M)


MULTIRATE = (*SETS, "time.dt=675.0", 'coupling.scheme="multirate"', "coupling.q=2")


def pinned_run(track, ranks=1, sets=SETS):
    """The run with pins; its output directory after checking that step 302
    alone was pinned and that every step converged."""
    out, p = run_track(track, scene("fault_reactivation"), *sets, ranks=ranks)
    lines, notes = PINNED.findall(p.stdout), re.findall(r"coupling iteration \d+: the (contact set cycles|converged "
                                                        r"iterate contradicts|iterate still contradicts)", p.stdout)
    s = summary(out)
    check(len(lines) == 1 and len(notes) == 1 and s["converged"] is True and s["pinned_windows"] == 1
          and s["steps"] == 302 and s.get("fallback_steps", 0) == 0,
          f"{track} ({ranks} rank{'s' if ranks > 1 else ''}{', multirate' if sets is MULTIRATE else ''}): step 302 "
          f"pinned, every step converged without the fallback: {lines}")
    return out


pinned = pinned_run("C++")
handed, p = run_track("C++", scene("fault_reactivation"), *SETS,
                      "coupling.pin_cycles=false", 'coupling.fallback="monolithic"')
check("the fixed-stress split cycles at t = 407700 (step 302)" in p.stdout and summary(handed)["fallback_steps"] == 1
      and summary(handed)["pinned_windows"] == 0,
      "C++: without pins the split cycles at step 302 and the monolithic scheme takes the step over")
d = max_difference(pinned, handed, FIELDS)
check(d["displacement"] <= 1e-9 and d["pressure"] <= 1e-7,
      f"C++: the pinned split equals the monolithic scheme's step 302: {d} (1e-9, 1e-7)")
two = pinned_run("C++", ranks=2)
d = max_difference(pinned, two, FIELDS, sort=True)
check(max(d.values()) <= 1e-8, f"C++: 2 ranks give 1 rank's pinned split: {d} (1e-8)")
prototype = pinned_run("prototype")
d = max_difference(pinned, prototype, FIELDS)
check(max(d.values()) <= 1e-9, f"the prototype gives the C++ pinned split: {d} (1e-9)")
multirate = summary(pinned_run("C++", sets=MULTIRATE))["fault_volumes"]["fault"]
imbalance = abs(multirate["injected"] + multirate["exchanged"] - multirate["stored"] - multirate["outflow"])
_, p = run_track("C++", scene("fault_reactivation"), *MULTIRATE, "coupling.pin_cycles=false",
                 'coupling.fallback="monolithic"')
check("the fixed-stress split cycles at t = 407700 (step 302)" in p.stdout
      and imbalance <= 1e-8 * multirate["injected"],
      f"C++: the multirate split (q = 2) cycles at window 302 without pins and converges with them, its volumes "
      f"balanced to {imbalance / multirate['injected']:.1e} of the injected (1e-8)")
