"""Mandel's problem (docs/verification.md, "Mandel") against its closed form: errors under
refinement of h and dt together (3 levels; orders >= 0.8), the fixed-stress
split and the monolithic solve agree, and the Mandel-Cryer effect (the
centre pressure first rising above its t = 0+ value) is reproduced. The
closed form is evaluated here independently of the solver's own."""
import math

import numpy as np
from support import Fields, check, run, scene, summary

# docs/verification.md check values for the scene's parameters.
lam, G, S, alpha, mobility, F, a = 1.65e9, 2.475e9, 1 / 1.65e10, 1.0, 9.869e-14 / 1e-3, 6.0e8, 100.0
K = lam + 2 * G / 3
nu = (3 * K - 2 * G) / (2 * (3 * K + G))
B = alpha / (S * (K + alpha ** 2 / S))
nu_u = (3 * nu + B * (1 - 2 * nu)) / (3 - B * (1 - 2 * nu))
c = 2 * mobility * B ** 2 * G * (1 - nu) * (1 + nu_u) ** 2 / (9 * (1 - nu_u) * (nu_u - nu))
check(abs(nu - 0.2) < 1e-6 and abs(B - 0.833333) < 1e-5 and abs(nu_u - 0.44) < 1e-5 and abs(c - 0.465253) < 1e-5,
      f"benchmark constants: nu {nu:.4f}, B {B:.6f}, nu_u {nu_u:.4f}, c {c:.6f}")
roots = []
for n in range(1, 200):
    lo, hi = (n - 1) * math.pi + 1e-12, (n - 1) * math.pi + math.pi / 2 - 1e-12
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if math.tan(mid) - (1 - nu) / (nu_u - nu) * mid < 0 else (lo, mid)
    roots.append(0.5 * (lo + hi))
check(np.allclose(roots[:3], [1.352522, 4.647934, 7.815616], atol=1e-6), "first roots as in docs/verification.md")


def p_exact(x, t):
    return 2 * F * B * (1 + nu_u) / (3 * a) * sum(
        math.sin(r) / (r - math.sin(r) * math.cos(r)) * (math.cos(r * x / a) - math.cos(r))
        * math.exp(-r * r * c * t / a ** 2) for r in roots)


LEVELS = [((20, 2), 40.0), ((40, 4), 20.0), ((80, 8), 10.0)]
errors = {}
for (nx, ny), dt in LEVELS:
    schemes = ("monolithic", "fixed-stress") if nx < 80 else ("monolithic",)
    for scheme in schemes:
        out, _ = run(scene("mandel"), "--set", f"mesh.cells=[{nx},{ny}]", "--set", f"time.dt={dt}",
                     "--set", f"coupling.scheme={scheme}", *(["--set", "output.xdmf=false"] if nx != 40 else []))
        e = summary(out)["errors"]
        errors[scheme, nx] = (e["pressure_rel_l2"], e["displacement_rel_l2"])
        if nx == 40 and scheme == "fixed-stress":
            fields = Fields(out)
            centre = int(np.argmin(np.linalg.norm(fields.cells, axis=1)))
            xc = fields.cells[centre, 0]
            times = fields.times("pressure")[1:]
            values = np.array([fields.at("pressure", t)[centre, 0] for t in times])
            exact = np.array([p_exact(xc, t) for t in times])
            check(values.max() > 1.01 * values[0] and np.argmax(values) > 0,
                  f"Mandel-Cryer: centre pressure rises from {values[0]:.4e} to {values.max():.4e} "
                  f"(exact {exact[0]:.4e} to {exact.max():.4e})")
            worst = np.abs(values - exact).max() / exact.max()
            check(worst <= 0.02, f"centre pressure history within {worst:.2%} of the closed form")
for (nx, _), _ in LEVELS[:2]:
    check(abs(errors["fixed-stress", nx][0] - errors["monolithic", nx][0]) <= 1e-6 * errors["monolithic", nx][0],
          f"{nx} cells across: split and monolithic pressure errors agree")
p40, u40 = errors["monolithic", 40]
check(p40 <= 0.02 and u40 <= 0.01, f"40 x 4 cells: pressure error {p40:.2e} <= 2%, displacement {u40:.2e} <= 1%")
for ((n0, _), _), ((n1, _), _) in zip(LEVELS, LEVELS[1:]):
    (p0, u0), (p1, u1) = errors["monolithic", n0], errors["monolithic", n1]
    check(math.log2(p0 / p1) >= 0.8, f"{n0}->{n1}: pressure order {math.log2(p0 / p1):.2f} >= 0.8 ({p0:.2e} -> {p1:.2e})")
    check(math.log2(u0 / u1) >= 0.8, f"{n0}->{n1}: displacement order {math.log2(u0 / u1):.2f} >= 0.8 ({u0:.2e} -> {u1:.2e})")
