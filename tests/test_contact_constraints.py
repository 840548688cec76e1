"""Signorini conditions at every contact node and every output time of the
default scene (alg. "Mechanics with frictionless Signorini contact"):
u.nu_F <= g_a, contact pressure >= 0, complementarity; and the contact set
grows while the block consolidates."""
from support import check, check_signorini, run, scene, summary

GAP = 0.0012  # scenes/default.toml, boundary.bottom.contact.gap; nu_F = -e_y
out, _ = run(scene("default"))
s = summary(out)
active_counts = check_signorini(out, GAP)
check(active_counts[0] == 0 and active_counts[-1] > active_counts[1] > 0,
      f"contact set grows with time: {active_counts}")
check(all(b >= a for a, b in zip(active_counts, active_counts[1:])), "contact set never shrinks under a fixed load")
c = s["contact"]
check(c["active_nodes"] == active_counts[-1], "summary reports the final active set")
check(c["max_penetration"] <= 1e-10 * c["gap_scale"], "summary: no penetration")
check(c["max_complementarity"] <= 1e-8 * c["max_contact_pressure"] * c["gap_scale"], "summary: complementarity")
