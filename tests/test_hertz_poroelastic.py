"""Poroelastic Hertz contact (docs/verification.md, "Hertz line contact"): under a fixed load the contact
half-width starts at the undrained Hertz value (E* with nu_u) and grows
monotonically to the drained one (nu), each within 5%. Geometrically growing
time steps (time.growth) reach both limits in 56 steps."""
import math

import numpy as np
from support import Fields, check, run, scene, summary

R, E, nu, M, alpha = 1.0, 1.0e9, 0.3, 1.0e12, 1.0
G = E / (2 * (1 + nu))
K = E / (3 * (1 - 2 * nu))
K_u = K + alpha ** 2 * M
nu_u = (3 * K_u - 2 * G) / (2 * (3 * K_u + G))

out, _ = run(scene("hertz_poroelastic"))
s = summary(out)
P = 2 * s["contact"]["total_force"]
check(abs(P - 2 * 5.0e6) <= 1e-8 * P, f"the foundation carries the load: P = {P:.6e} N/m")
fields = Fields(out)
x, y = fields.nodes[:, 0], fields.nodes[:, 1]
arc = np.isclose(np.hypot(x, y - R), R)
widths = []
for t in fields.times("contact_active")[1:]:
    active = fields.at("contact_active", t)[:, 0] > 0.5
    last = x[arc & active].max()
    widths.append(0.5 * (last + x[arc & (x > last)].min()))


def hertz(poisson):
    return math.sqrt(4 * P * R / (math.pi * 2 * G / (1 - poisson)))


a_u, a_d = hertz(nu_u), hertz(nu)
check(abs(widths[0] - a_u) <= 0.05 * a_u, f"t = 0+: half-width {widths[0]:.4f} vs undrained Hertz {a_u:.4f}")
check(abs(widths[-1] - a_d) <= 0.05 * a_d, f"t -> infinity: half-width {widths[-1]:.4f} vs drained Hertz {a_d:.4f}")
check(all(b >= a for a, b in zip(widths, widths[1:])), "the half-width grows monotonically")
check(len(widths) == s["steps"] == 56, f"{s['steps']} growing steps to t = 2000 s")
