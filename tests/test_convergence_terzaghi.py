"""Terzaghi under refinement of h and dt together (4 levels, h and dt halved
each time), with the fixed-stress split and the monolithic solve: the
observed orders of the P0 pressure error (relative L2, final time) are
>= 0.8 (first order expected: P0 in space, backward Euler in time), those of
the displacement >= 0.75 (first order in dt dominates), and both schemes
give the same errors."""
import math

from support import check, run, scene, summary

LEVELS = [(10, 0.04), (20, 0.02), (40, 0.01), (80, 0.005)]
errors = {}
for scheme in ("fixed-stress", "monolithic"):
    for cells, dt in LEVELS:
        out, _ = run(scene("terzaghi"), "--set", f"mesh.cells=[1,{cells}]", "--set", f"time.dt={dt}",
                     "--set", f"coupling.scheme={scheme}", "--set", "output.xdmf=false")
        e = summary(out)["errors"]
        errors[scheme, cells] = (e["pressure_rel_l2"], e["displacement_rel_l2"])
    for (c0, _), (c1, _) in zip(LEVELS, LEVELS[1:]):
        (p0, u0), (p1, u1) = errors[scheme, c0], errors[scheme, c1]
        order_p, order_u = math.log2(p0 / p1), math.log2(u0 / u1)
        check(order_p >= 0.8, f"{scheme} {c0}->{c1} cells: pressure error {p0:.3e} -> {p1:.3e}, order {order_p:.2f} >= 0.8")
        check(order_u >= 0.75, f"{scheme} {c0}->{c1} cells: displacement error {u0:.3e} -> {u1:.3e}, order {order_u:.2f} >= 0.75")
for cells, _ in LEVELS:
    a, b = errors["fixed-stress", cells], errors["monolithic", cells]
    check(abs(a[0] - b[0]) <= 1e-6 * b[0], f"{cells} cells: split and monolithic pressure errors agree")
