"""The converged split equals the monolithic solve (docs/theory.md, "Monolithic
reference") on the default scene, whose contact set changes during the run;
and the monolithic VI satisfies the Signorini conditions at every node;
with faults it records their seismic moment as the split does."""
import numpy as np
from support import check, check_signorini, max_difference, run, run_track, scene, summary

mono, _ = run(scene("default"), "--set", "coupling.scheme=monolithic")
split, _ = run(scene("default"), "--set", "coupling.tolerance=1e-12", "--set", "coupling.max_iterations=400")
s = summary(mono)
check(s["monolithic_solves"] == 48 and s["flow_solves"] == 0 and s["mechanics_solves"] == 0,
      "monolithic: one coupled solve per step, no split solves")
counts = check_signorini(mono, 0.0012, label="monolithic ")
check(counts[-1] > counts[1] > 0, f"monolithic: the contact set grows {counts}")
check(counts == check_signorini(split, 0.0012, label="split "), "split and monolithic: same active sets")
for name, d in max_difference(mono, split, ("displacement", "pressure", "flux")).items():
    check(d <= 1e-6, f"{name}: split vs monolithic max relative difference {d:.1e} <= 1e-6")

# Growing time steps (time.growth): both reassemble their dt-dependent
# matrices at every step and still agree.
growth = ["--set", "time.dt=0.001", "--set", "time.growth=1.1", "--set", "coupling.tolerance=1e-12"]
mono, _ = run(scene("terzaghi"), *growth, "--set", "coupling.scheme=monolithic")
split, _ = run(scene("terzaghi"), *growth)
check(summary(mono)["steps"] == summary(split)["steps"] == 49, "49 growing steps to t = 1")
for name, d in max_difference(mono, split, ("displacement", "pressure", "flux")).items():
    check(d <= 1e-6, f"growing steps, {name}: split vs monolithic {d:.1e} <= 1e-6")

# Faults: the monolithic solve records each fault's seismic moment step by
# step as the split does (summary.json's seismic_moment), on both tracks;
# the frictional fault of scenes/fault_reactivation.toml slips under
# injection.
moments = {}
for track in ("C++", "prototype"):
    for scheme in ("monolithic", "fixed-stress"):
        out, _ = run_track(track, scene("fault_reactivation"), f"coupling.scheme={scheme}", "coupling.tolerance=1e-10")
        moments[track, scheme] = summary(out)["seismic_moment"]["fault"]
    a, b = moments[track, "monolithic"], moments[track, "fixed-stress"]
    difference = np.abs(np.array(a["moments"]) - np.array(b["moments"])).max() / b["total"]
    check(a["times"] == b["times"] and len(a["times"]) == 30 and b["total"] > 0 and difference <= 1e-6,
          f"{track}: the monolithic solve's seismic moment of each of its {len(a['times'])} steps is the split's to "
          f"{difference:.1e} of the total {b['total']:.4e} N m (1e-6)")
same = abs(moments["prototype", "monolithic"]["total"] / moments["C++", "monolithic"]["total"] - 1)
check(same <= 1e-8, f"monolithic: the prototype's total moment is the C++ one's to {same:.1e} (1e-8)")
