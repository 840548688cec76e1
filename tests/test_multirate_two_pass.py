"""The two-pass multirate variant (coupling.scheme = "multirate-two-pass",
issue 13; docs/multirate-two-pass.md) on the default scene (its contact set
changing):
- q = 1 is the single-rate scheme: identical iterations, the same fields to
  1e-12 (the second pass is skipped: its correction would return p^A_1);
- it has the fixed point of the printed multirate scheme: at coupling
  tolerance 1e-12 both (and the variant with Anderson acceleration) agree to
  1e-8 relative in every field, with the same active sets;
- one iteration costs 2q flow solves and one mechanics solve;
- its contraction, asserted as found: the ratio of Theorem 2's quantity
  stays at the single-rate level, never above gamma, in at most twice the
  coupling iterations per mechanics step of single rate (docs/verification.md)."""
from support import check, check_signorini, iterations, max_difference, run, scene, summary

VARIANT = ["--set", "coupling.scheme=multirate-two-pass"]
TIGHT = ["--set", "coupling.tolerance=1e-12", "--set", "coupling.max_iterations=2000"]
FIELDS = ("displacement", "pressure", "flux", "contact_pressure")

single, _ = run(scene("default"))
s_single = summary(single)
variant1, _ = run(scene("default"), *VARIANT, "--set", "coupling.q=1")
check([r["iteration"] for r in iterations(single)] == [r["iteration"] for r in iterations(variant1)],
      "q = 1: identical coupling iterations in every step")
for name, d in max_difference(single, variant1, FIELDS).items():
    check(d <= 1e-12, f"q = 1: {name} max relative difference {d:.1e} <= 1e-12")

printed, _ = run(scene("default"), "--set", "coupling.scheme=multirate", "--set", "coupling.q=4", *TIGHT)
for label, extra in (("variant", []), ("variant with Anderson", ["--set", "coupling.acceleration=anderson"])):
    out, _ = run(scene("default"), *VARIANT, "--set", "coupling.q=4", *TIGHT, *extra)
    check(summary(out)["converged"], f"{label}, q = 4, tolerance 1e-12: converged "
          f"({summary(out)['coupling_iterations']} iterations, printed {summary(printed)['coupling_iterations']})")
    for name, d in max_difference(out, printed, FIELDS).items():
        check(d <= 1e-8, f"{label} vs printed multirate (q = 4, tolerance 1e-12): {name} {d:.1e} <= 1e-8")
    counts = check_signorini(out, 0.0012, label=f"{label} ")
    check(counts == check_signorini(printed, 0.0012, label="printed "), f"{label}: same active sets {counts}")

per_step_single = s_single["coupling_iterations"] / s_single["steps"]
for q in (4, 8):
    s = summary(run(scene("default"), *VARIANT, "--set", f"coupling.q={q}")[0])
    check(s["converged"] and s["scheme"] == "multirate-two-pass" and s["steps"] == s_single["steps"] // q,
          f"q = {q}: converged in {s['steps']} mechanics steps")
    check(s["flow_solves"] == 2 * q * s["coupling_iterations"] and s["mechanics_solves"] == s["coupling_iterations"],
          f"q = {q}: {s['flow_solves']} flow solves = 2q x {s['coupling_iterations']} iterations")
    check(s["bound_violations"] == 0 and s["max_contraction_ratio"] <= 1.02 * s_single["max_contraction_ratio"],
          f"q = {q}: max ratio {s['max_contraction_ratio']:.4f} at the single-rate level "
          f"{s_single['max_contraction_ratio']:.4f} (gamma {s['gamma']:.4f})")
    per_step = s["coupling_iterations"] / s["steps"]
    check(per_step <= 2 * per_step_single,
          f"q = {q}: {per_step:.1f} coupling iterations per mechanics step <= 2 x {per_step_single:.1f} (single rate)")
