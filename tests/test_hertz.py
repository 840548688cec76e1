"""Hertz line contact (docs/verification.md, "Hertz line contact"): an elastic cylinder pressed on a rigid
flat (pure mechanics, no flow allocated), gmsh mesh refined near the
contact. With P the measured load, the contact half-width and the peak
contact pressure are within 5% of a = sqrt(4PR/(pi E*)), p_max = 2P/(pi a)."""
import math

import numpy as np
from support import Fields, check, run, scene, summary

R, E, nu = 1.0, 1.0e9, 0.3
out, _ = run(scene("hertz"))
s = summary(out)
check(set(s["dofs"]) == {"displacement"} and s["flow_solves"] == 0, "pure mechanics: no flow unknowns")
fields = Fields(out)
t = fields.times("contact_pressure")[-1]
x, y = fields.nodes[:, 0], fields.nodes[:, 1]
arc = np.isclose(np.hypot(x, y - R), R)
active = fields.at("contact_active", t)[:, 0] > 0.5
pressure = fields.at("contact_pressure", t)[:, 0]
last = x[arc & active].max()
following = x[arc & (x > last)].min()
a_measured = 0.5 * (last + following)        # the edge lies between the two nodes
P = 2 * s["contact"]["total_force"]          # half model
E_star = E / (1 - nu ** 2)
a = math.sqrt(4 * P * R / (math.pi * E_star))
p_max = 2 * P / (math.pi * a)
check(a / R < 0.15, f"a/R = {a / R:.3f}: the Hertz theory applies")
check(abs(a_measured - a) <= 0.05 * a, f"half-width {a_measured:.4f} vs Hertz {a:.4f} ({abs(a_measured - a) / a:.1%})")
check(abs(pressure[arc].max() - p_max) <= 0.05 * p_max,
      f"peak pressure {pressure[arc].max():.4e} vs Hertz {p_max:.4e} ({abs(pressure[arc].max() - p_max) / p_max:.1%})")
inside = arc & active & (x < 0.8 * a)
profile = p_max * np.sqrt(1 - (x[inside] / a) ** 2)
worst = np.abs(pressure[inside] - profile).max() / p_max
check(worst <= 0.05, f"pressure profile within {worst:.1%} of p_max sqrt(1 - x^2/a^2) for x < 0.8 a")
