"""Terzaghi consolidation against its closed form (docs/verification.md, "Terzaghi")."""
from support import check, run, scene, summary

out, _ = run(scene("terzaghi"))
s = summary(out)
e = s["errors"]
check(s["converged"], "the split converged in every step")
check(e["pressure_rel_l2"] <= 0.02, f"pressure relative L2 error {e['pressure_rel_l2']:.3e} <= 2%")
check(e["settlement_rel"] <= 0.01, f"settlement error {e['settlement_rel']:.3e} <= 1%")
check(e["displacement_rel_l2"] <= 0.01, f"displacement relative L2 error {e['displacement_rel_l2']:.3e} <= 1%")
check("contact" not in s and "contact solver" in s["left_out"], "no contact solver without contact")
