"""Multirate with q = 1 is the single-rate scheme (docs/theory.md, "Multirate fixed-stress split"): the same
fields in every step to 1e-12 relative, and identical iteration counts."""
from support import check, iterations, max_difference, run, scene

single, _ = run(scene("default"))
multi, _ = run(scene("default"), "--set", "coupling.scheme=multirate", "--set", "coupling.q=1")
check([r["iteration"] for r in iterations(single)] == [r["iteration"] for r in iterations(multi)],
      "identical coupling iterations in every step")
for name, d in max_difference(single, multi, ("displacement", "pressure", "flux", "contact_pressure")).items():
    check(d <= 1e-12, f"{name}: max relative difference {d:.1e} <= 1e-12")
