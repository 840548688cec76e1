"""Foundations of any shape (issue 23), on the C++ solver and the prototype:
- a rigid cylinder indenting an elastic block (scenes/indenter.toml, gap and
  normal from the cylinder): Hertz's half-width and peak pressure within 2 %;
- a rigid sphere indenting an elastic block in 3D (scenes/indenter3d.toml,
  quarter model): contact radius a = (3 P R / (4 E*))^(1/3) and peak
  3 P / (2 pi a^2) within 3 %;
- a wedge pressed into a frictionless V-groove (scenes/groove.toml, two
  contact boundaries with normals at +-30 degrees): each flank's resultant
  equals F / (2 cos 30 deg) to 1e-8, the apex node holds both constraints,
  and the full path (its first step's singular reduced system answered by the
  clamped start) the same fields to 1e-10, no CHOLMOD warning on the terminal.
P is measured: the vertical resultant of the nodes' contact pressures."""
import itertools
import math

import numpy as np
from support import Fields, check, max_difference, run_track, scene, summary

R, E, NU = 1.0, 1.0e9, 0.3
E_STAR = E / (1 - NU ** 2)


def top_measures(fields, d):
    """Each top node's share of the top's length (2D) or area (3D)."""
    x, top = fields.nodes, np.isclose(fields.nodes[:, d - 1], 0.0)
    w = np.zeros(len(x))
    for cell in fields.topology:
        for facet in itertools.combinations(cell, d):
            facet = list(facet)
            if top[facet].all():
                edges = x[facet[1:]] - x[facet[0]]
                size = np.linalg.norm(edges[0]) if d == 2 else np.linalg.norm(np.cross(edges[0], edges[1])) / 2
                w[facet] += size / d
    return top, w


def indentation(out, d):
    """(P, largest active and smallest inactive radius, peak pressure)."""
    fields = Fields(out)
    t = fields.times("contact_pressure")[-1]
    top, w = top_measures(fields, d)
    r = np.linalg.norm(fields.nodes[:, :d - 1], axis=1)
    pressure = fields.at("contact_pressure", t)[:, 0]
    active = fields.at("contact_active", t)[:, 0] > 0.5
    vertical = R / np.sqrt(r ** 2 + R ** 2)  # the normal's vertical component
    P = (2 if d == 2 else 4) * np.sum((pressure * w * vertical)[top])  # half or quarter model
    return P, r[top & active].max(), r[top & ~active & (r > 0)].min(), pressure[top].max()


for track in ("C++", "prototype"):
    out, _ = run_track(track, scene("indenter"))
    P, inside, outside, peak = indentation(out, 2)
    a = math.sqrt(4 * P * R / (math.pi * E_STAR))
    p_max = 2 * P / (math.pi * a)
    measured = 0.5 * (inside + outside)  # the edge lies between the two nodes
    check(a / R < 0.15 and abs(measured - a) <= 0.02 * a,
          f"cylinder ({track}): half-width {measured:.5f} vs Hertz {a:.5f} ({(measured - a) / a:+.2%})")
    check(abs(peak - p_max) <= 0.02 * p_max,
          f"cylinder ({track}): peak pressure {peak:.4e} vs Hertz {p_max:.4e} ({(peak - p_max) / p_max:+.2%})")

    out, _ = run_track(track, scene("indenter3d"))
    P, inside, outside, peak = indentation(out, 3)
    a = (3 * P * R / (4 * E_STAR)) ** (1 / 3)
    p_max = 3 * P / (2 * math.pi * a ** 2)
    check(a / R < 0.15 and max(abs(inside - a), abs(outside - a)) <= 0.03 * a,
          f"sphere ({track}): contact radius between {outside:.5f} and {inside:.5f} (the nodes either side of "
          f"the edge) vs Hertz {a:.5f} ({(outside - a) / a:+.2%}, {(inside - a) / a:+.2%})")
    check(abs(peak - p_max) <= 0.03 * p_max,
          f"sphere ({track}): peak pressure {peak:.4e} vs Hertz {p_max:.4e} ({(peak - p_max) / p_max:+.2%})")

    out, _ = run_track(track, scene("groove"))
    c = summary(out)["contact"]
    F = 1.0e6 * 2.0
    expected = F / (2 * math.cos(math.radians(30)))
    for flank in ("left_flank", "right_flank"):
        force = c["boundaries"][flank]["force"]
        check(abs(force - expected) <= 1e-8 * expected,
              f"groove ({track}): {flank} resultant {force:.10e} vs F/(2 cos 30) {expected:.10e} "
              f"({abs(force - expected) / expected:.1e})")
    fields = Fields(out)
    t = fields.times("contact_active")[-1]
    apex = np.argmin(np.linalg.norm(fields.nodes, axis=1))
    nodes = int(fields.at("contact_boundary", fields.times("contact_boundary")[0])[:, 0].sum())
    check(c["contact_nodes"] == nodes + 1 and c["boundaries"]["left_flank"]["active_nodes"]
          + c["boundaries"]["right_flank"]["active_nodes"] == c["contact_nodes"]
          and fields.at("contact_active", t)[apex, 0] == 1.0,
          f"groove ({track}): {c['contact_nodes']} constraints on {nodes} nodes, all active: the apex holds two")
    full, p = run_track(track, scene("groove"), options=("-mechanics_contact_condensed", "false"))
    d = max_difference(out, full, ["displacement", "contact_pressure"])
    check(max(d.values()) <= 1e-10 and "CHOLMOD" not in p.stdout + p.stderr,
          f"groove ({track}): the full path, restarted clamped after its zero pivot, gives the condensed fields to "
          f"{max(d.values()):.1e} (1e-10), quietly")
