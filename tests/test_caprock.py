"""The caprock scene (issue 22, item 4): CO2 injected below a caprock whose
fracture zone above the well jacks open (regions from gmsh cell groups, a
well, a contact face loaded by the pore pressure beside it), to day 16:
- the contact set only shrinks, from all 151 face nodes closed to fewer than
  10, and the fracture opens from its base: the open part is one interval from
  within 10 m of its base, its upper end rising;
- Signorini holds at every face node and time (no penetration of the
  symmetry plane, contact pressure >= 0, complementarity);
- the regions hold the cells of their gmsh groups;
- 2 ranks reach the same contact sets and fields, the monolithic solve the
  split's contact sets;
- the prototype gives the C++ run (fields, iterations, contact sets)."""
import numpy as np

from support import (TRACKS, Fields, Foundation, check, check_contact_scene_agrees, check_signorini, run_track, scene,
                     summary)

CAPROCK = scene("caprock")
END = "time.end=1382400"  # 16 days
BOTTOM, TOP = -1800.0, -1650.0


def face_nodes(fields):
    on = np.flatnonzero(np.isclose(fields.nodes[:, 0], 0.0) & (fields.nodes[:, 1] >= BOTTOM - 1e-9)
                        & (fields.nodes[:, 1] <= TOP + 1e-9))
    return on[np.argsort(fields.nodes[on, 1])]


def active_sets(out):
    fields = Fields(out)
    nodes = face_nodes(fields)
    return [fields.at("contact_active", t)[nodes, 0] > 0.5 for t in fields.times("displacement")]


runs = {}
for track in TRACKS:
    runs[track], _ = run_track(track, CAPROCK, END)
out = runs["C++"]
sets = active_sets(out)
counts = [int(s.sum()) for s in sets]
check(counts[0] == len(sets[0]) == 151 and counts[-1] < 10 and all(b <= a for a, b in zip(counts, counts[1:])),
      f"the contact set only shrinks, from the whole face to the jacked fracture ({counts})")
fields = Fields(out)
y = fields.nodes[face_nodes(fields), 1]
front = BOTTOM
for t, closed in zip(fields.times("displacement"), sets):
    open_y = y[~closed]
    if len(open_y):
        interval = ~closed[(y >= open_y.min()) & (y <= open_y.max())]
        check(open_y.min() <= BOTTOM + 10.0 and interval.all() and open_y.max() >= front,
              f"day {t / 86400:.0f}: the open part is one interval from near the base, its front rising "
              f"({open_y.min():.0f} m to {open_y.max():.0f} m)")
        front = open_y.max()
check_signorini(out, 0.0, Foundation(axis=0), pressure_scale="run")
regions = summary(out)["regions"]
check(all(regions[name]["cells"] > 0 for name in ("reservoir", "fracture_zone")) and regions["no region"]["cells"] > 0,
      f"the regions hold the cells of their groups ({ {k: v['cells'] for k, v in regions.items()} })")

check_contact_scene_agrees(CAPROCK, sets, active_sets, runs, END)
