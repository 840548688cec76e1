"""The borehole scene (issue 23, item 4): a weak formation closing onto an
off-centre sand screen during the production drawdown, a curved foundation
whose gap and normal come from the screen. On the C++ solver:
- the contact arc starts at the low side and only grows, and at every time
  it is one arc from the lowest point of the wall;
- Signorini holds at every wall node and time, in the screen's normal
  direction (no penetration, contact pressure >= 0, complementarity);
- the wall converges everywhere (the drawdown unloads it);
- 2 ranks reach the same contact sets and the same fields (1e-8);
- the monolithic solve reaches the same contact sets, and the split at
  coupling tolerance 1e-12 its fields;
- the prototype gives the C++ run (fields, iterations, contact sets)."""
import numpy as np

from support import TRACKS, Fields, Foundation, check, check_contact_scene_agrees, check_signorini, run_track, scene

BOREHOLE = scene("borehole")
R_WALL, R_SCREEN, E = 0.108, 0.0762, 0.0316  # hole and screen radii, the screen's centre (0, -E)


def on_wall(x):
    return np.isclose(np.hypot(x[:, 0], x[:, 1]), R_WALL, atol=1e-6)


def to_screen(x):
    """The vector from wall nodes to the screen's centre, and its length."""
    v = np.stack([-x[:, 0], -E - x[:, 1]], axis=1)
    return v, np.linalg.norm(v, axis=1)


def wall_sets(out):
    """Each output time's active flags on the wall, ordered from the lowest
    point up, and the angle of each node from the lowest point (degrees)."""
    fields = Fields(out)
    nodes = np.flatnonzero(on_wall(fields.nodes))
    angle = np.degrees(np.arctan2(fields.nodes[nodes, 0], -fields.nodes[nodes, 1]))
    order = np.argsort(angle)
    nodes, angle = nodes[order], angle[order]
    return [fields.at("contact_active", t)[nodes, 0] > 0.5 for t in fields.times("displacement")], angle, fields


runs = {}
for track in TRACKS:
    runs[track], _ = run_track(track, BOREHOLE)
out = runs["C++"]
sets, angle, fields = wall_sets(out)
counts = [int(s.sum()) for s in sets]
check(counts[0] == 0 and counts[-1] >= 4 and all(b >= a for a, b in zip(counts, counts[1:])),
      f"the contact arc only grows, from none ({counts})")
arcs = [s.sum() == 0 or (s[0] and not s[int(s.sum()):].any()) for s in sets]
check(all(arcs), f"at every time one arc from the lowest point (to {angle[sets[-1]].max():.1f} degrees at the end)")
check_signorini(out, lambda x: to_screen(x)[1] - R_SCREEN,
                Foundation(side=on_wall, normal=lambda x: to_screen(x)[0] / to_screen(x)[1][:, None]),
                pressure_scale="run")
t = fields.times("displacement")[-1]
x = fields.nodes[on_wall(fields.nodes)]
u = fields.at("displacement", t)[on_wall(fields.nodes)]
radial = np.sum(u[:, :2] * x[:, :2], axis=1) / R_WALL
check(radial.max() < 0, f"the wall converges everywhere (radial displacement {radial.min():.2e} to {radial.max():.2e} m)")

check_contact_scene_agrees(BOREHOLE, sets, lambda out: wall_sets(out)[0], runs)
