"""Signorini conditions at every contact node and every output time of the
default scene (alg. "Mechanics with frictionless Signorini contact"):
u.nu_F <= g_a, contact pressure >= 0, complementarity; and the contact set
grows while the block consolidates."""
import numpy as np
from support import Fields, check, run, scene, summary

GAP = 0.0012  # scenes/default.toml, boundary.bottom.contact.gap; nu_F = -e_y
out, _ = run(scene("default"))
s = summary(out)
fields = Fields(out)
bottom = np.isclose(fields.nodes[:, 1], 0.0)
active_counts = []
for t in fields.times("displacement"):
    u_nu = -fields.at("displacement", t)[bottom, 1]          # u.nu_F with nu_F = -e_y
    p_c = fields.at("contact_pressure", t)[bottom, 0]
    active = fields.at("contact_active", t)[bottom, 0]
    scale = max(GAP, np.abs(u_nu).max())
    p_scale = max(p_c.max(), 1e-300)
    check((u_nu - GAP).max() <= 1e-10 * scale, f"t={t:g}: no penetration (max u.nu - g = {(u_nu - GAP).max():.2e})")
    if active.sum() > 0:
        check(p_c.min() >= -1e-8 * p_scale, f"t={t:g}: contact pressure >= 0 (min {p_c.min():.2e}, max {p_scale:.2e})")
        comp = np.abs(p_c * (u_nu - GAP)).max()
        check(comp <= 1e-8 * p_scale * scale, f"t={t:g}: complementarity {comp:.2e}")
    active_counts.append(int(active.sum()))
check(active_counts[0] == 0 and active_counts[-1] > active_counts[1] > 0,
      f"contact set grows with time: {active_counts}")
check(all(b >= a for a, b in zip(active_counts, active_counts[1:])), "contact set never shrinks under a fixed load")
c = s["contact"]
check(c["active_nodes"] == active_counts[-1], "summary reports the final active set")
check(c["max_penetration"] <= 1e-10 * c["gap_scale"], "summary: no penetration")
check(c["max_complementarity"] <= 1e-8 * c["max_contact_pressure"] * c["gap_scale"], "summary: complementarity")
