"""Rotation invariance of contact on an inclined foundation (issue 23): the
default scene on a gmsh mesh, and the same scene built in a frame rotated
by 30 degrees (the same mesh with its nodes rotated, the top's traction and
the foundation's normal rotated) give the same contact sets at every output
time, the same coupling iterations (+-1), and contact pressures and
rotated-back fields equal to 1e-8 relative; split (direct and iterative
solvers) and monolithic, on the C++ solver and the prototype (split,
direct). The axis frame runs without a change of variables, the rotated one
with a rotation at every contact node: what the test compares is the change
of variables against no change."""
import os
import re
import subprocess
import tempfile

import numpy as np
from support import ROOT, Fields, check, iterations, run_track, scene, written

ANGLE = np.radians(30.0)
R = np.array([[np.cos(ANGLE), -np.sin(ANGLE)], [np.sin(ANGLE), np.cos(ANGLE)]])


def meshes():
    """The cantilever's gmsh mesh, and the same mesh with its nodes rotated."""
    folder = tempfile.mkdtemp()
    base, rotated = os.path.join(folder, "base.msh"), os.path.join(folder, "rotated.msh")
    subprocess.run(["gmsh", "-2", os.path.join(ROOT, "meshes", "cantilever.geo"), "-format", "msh22", "-o", base],
                   check=True, capture_output=True)
    lines = open(base).read().splitlines()
    first = lines.index("$Nodes") + 2
    for k in range(first, first + int(lines[first - 1])):
        i, x, y, z = lines[k].split()
        X, Y = R @ [float(x), float(y)]
        lines[k] = f"{i} {X!r} {Y!r} {z}"
    with open(rotated, "w") as f:
        f.write("\n".join(lines) + "\n")
    return base, rotated


def scene_on(mesh, rotated, extra=""):
    with open(scene("default")) as f:
        text = f.read()
    text = re.sub(r"\[mesh\]\n(.*\n)*?(?=\n\[)", f'[mesh]\ntype = "gmsh"\nfile = "{mesh}"\n', text)
    if rotated:
        traction, normal = R @ [0.0, -1.0e3], R @ [0.0, -1.0]
        text = text.replace("traction = [0.0, -1.0e3]", f"traction = [{traction[0]!r}, {traction[1]!r}]")
        text = text.replace("normal = [0.0, -1.0]", f"normal = [{normal[0]!r}, {normal[1]!r}]")
    return written(text + extra)


def matched(base, turned):
    """The order of the rotated run's nodes that matches the base run's."""
    back = turned.nodes[:, :2] @ R  # R^T x for each row x
    key = lambda x: np.lexsort(np.round(x, 8).T[::-1])
    order_base, order_turned = key(base.nodes[:, :2]), key(back)
    check(np.abs(base.nodes[order_base, :2] - back[order_turned]).max() < 1e-9, "the rotated mesh maps onto the base")
    index = np.empty(len(order_base), dtype=int)
    index[order_base] = order_turned
    return index


def per_step(out):
    """Coupling iterations of each step (none for the monolithic scheme)."""
    steps = {}
    for row in iterations(out):
        steps[int(row["step"])] = int(row["iteration"])
    return [steps[k] for k in sorted(steps)]


def compare(label, base_out, turned_out):
    a, b = Fields(base_out), Fields(turned_out)
    index = matched(a, b)
    cells = np.lexsort(np.round(a.cells[:, :2], 8).T[::-1]), np.lexsort(np.round(b.cells[:, :2] @ R, 8).T[::-1])
    ia, ib = per_step(base_out), per_step(turned_out)
    check(len(ia) == len(ib) and all(abs(x - y) <= 1 for x, y in zip(ia, ib)),
          f"{label}: the same coupling iterations (+-1) in all {len(ia)} steps ({sum(ia)} and {sum(ib)})")
    times = a.times("contact_active")
    check(times == b.times("contact_active"), f"{label}: the same output times")
    sets = [np.array_equal(a.at("contact_active", t)[:, 0], b.at("contact_active", t)[index, 0]) for t in times]
    active = [int(a.at("contact_active", t).sum()) for t in times]
    check(all(sets) and active[-1] > 0, f"{label}: the same contact sets at all {len(times)} times (active {active})")
    worst = {}
    for t in times:
        p, q = a.at("contact_pressure", t)[:, 0], b.at("contact_pressure", t)[index, 0]
        u, v = a.at("displacement", t)[:, :2], b.at("displacement", t)[index, :2] @ R
        pa, pb = a.at("pressure", t)[cells[0], 0], b.at("pressure", t)[cells[1], 0]
        for name, x, y in (("contact_pressure", p, q), ("displacement", u, v), ("pressure", pa, pb)):
            scale = np.abs(x).max()
            worst[name] = max(worst.get(name, 0.0), np.abs(x - y).max() / scale if scale > 0 else 0.0)
    check(max(worst.values()) <= 1e-8, f"{label}: contact pressure and rotated-back fields equal to 1e-8 relative "
          f"({', '.join(f'{k} {v:.1e}' for k, v in worst.items())})")


base_mesh, turned_mesh = meshes()
CASES = [("split, direct", "C++", ""),
         ("split, iterative", "C++", '\n[solver]\nflow = "iterative"\nmechanics = "iterative"\n'),
         ("monolithic", "C++", ""),
         ("split, direct", "prototype", "")]
for label, track, extra in CASES:
    sets = ("coupling.scheme=monolithic",) if label == "monolithic" else ()
    base_out, _ = run_track(track, scene_on(base_mesh, False, extra), "time.end=4.8", *sets)
    turned_out, _ = run_track(track, scene_on(turned_mesh, True, extra), "time.end=4.8", *sets)
    compare(f"{label} ({track})", base_out, turned_out)
