"""The converged split equals the monolithic solve (docs/theory.md, "Monolithic
reference") on the default scene, whose contact set changes during the run;
and the monolithic VI satisfies the Signorini conditions at every node."""
from support import check, check_signorini, max_difference, run, scene, summary

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
