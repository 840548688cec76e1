"""Terzaghi with the base on frictionless contact at zero gap equals Terzaghi
with a fixed base (docs/verification.md, "Properties any split must show"): the base is held by the foundation alone
(semi-coercive), so this also exercises the contact solver's clamped start."""
from support import check, check_signorini, iterations, max_difference, run, scene, summary

fixed, _ = run(scene("terzaghi"))
contact, _ = run(scene("terzaghi_contact"))
s = summary(contact)
check(s["contact"]["active_nodes"] == s["contact"]["contact_nodes"] > 0, "the whole base is in contact")
check_signorini(contact, 0.0, label="contact base ")
check([r["iteration"] for r in iterations(fixed)] == [r["iteration"] for r in iterations(contact)],
      "identical coupling iterations in every step")
for name, d in max_difference(fixed, contact, ("displacement", "pressure", "flux")).items():
    check(d <= 1e-9, f"{name}: contact base vs fixed base max relative difference {d:.1e} <= 1e-9")
check(abs(s["errors"]["pressure_rel_l2"] - summary(fixed)["errors"]["pressure_rel_l2"]) < 1e-9,
      "the same error against the closed form")
