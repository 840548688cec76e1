"""Rotation invariance of contact on an inclined foundation (issue 23): the
default scene on a gmsh mesh, and the same scene built in a frame rotated
by 30 degrees (the same mesh with its nodes rotated, the top's traction and
the foundation's normal rotated) give the same contact sets at every output
time, the same coupling iterations (+-1), and contact pressures and
rotated-back fields equal to 1e-8 relative; split and monolithic, direct
and iterative solvers, on the C++ solver, and direct on the prototype. The
same for the 3D block rotated by 30 degrees about (1, 1, 1). The axis frame runs without a change of variables, the rotated one with a
rotation at every contact node: what the test compares is the change of
variables against no change."""
import os
import tempfile

import numpy as np
from support import ROOT, Fields, check, iterations, run_track, scene, written
from tools.rotate_mesh import mesh, on_mesh, rotate_msh, rotate_scene, rotation

R = {2: rotation(30.0, 2), 3: rotation(30.0, 3, (1.0, 1.0, 1.0))}


def meshes(geo, d):
    """A geometry's gmsh mesh, and the same mesh with its nodes rotated."""
    folder = tempfile.mkdtemp()
    base, rotated = os.path.join(folder, "base.msh"), os.path.join(folder, "rotated.msh")
    mesh(os.path.join(ROOT, "meshes", geo), d, base)
    rotate_msh(base, rotated, R[d])
    return base, rotated


def scene_on(name, mesh_file, d, rotated, extra=""):
    """The scene on a mesh file; rotated, its traction and normal rotated."""
    with open(scene(name)) as f:
        text = f.read()
    text = on_mesh(text, mesh_file, d)
    return written((rotate_scene(text, R[d]) if rotated else text) + extra)


def order(x):
    return np.lexsort(np.round(x, 8).T[::-1])


def matched(base, turned, d):
    """The order of the rotated run's nodes that matches the base run's."""
    back = turned.nodes[:, :d] @ R[d]  # R^T x for each row x
    order_base, order_turned = order(base.nodes[:, :d]), order(back)
    check(np.abs(base.nodes[order_base, :d] - back[order_turned]).max() < 1e-9, "the rotated mesh maps onto the base")
    index = np.empty(len(order_base), dtype=int)
    index[order_base] = order_turned
    return index


def per_step(out):
    """Coupling iterations of each step (none for the monolithic scheme)."""
    steps = {}
    for row in iterations(out):
        steps[int(row["step"])] = int(row["iteration"])
    return [steps[k] for k in sorted(steps)]


def compare(label, base_out, turned_out, d):
    a, b = Fields(base_out), Fields(turned_out)
    index = matched(a, b, d)
    cells = order(a.cells[:, :d]), order(b.cells[:, :d] @ R[d])
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
        u, v = a.at("displacement", t)[:, :d], b.at("displacement", t)[index, :d] @ R[d]
        pa, pb = a.at("pressure", t)[cells[0], 0], b.at("pressure", t)[cells[1], 0]
        for name, x, y in (("contact_pressure", p, q), ("displacement", u, v), ("pressure", pa, pb)):
            scale = np.abs(x).max()
            worst[name] = max(worst.get(name, 0.0), np.abs(x - y).max() / scale if scale > 0 else 0.0)
    check(max(worst.values()) <= 1e-8, f"{label}: contact pressure and rotated-back fields equal to 1e-8 relative "
          f"({', '.join(f'{k} {v:.1e}' for k, v in worst.items())})")


ITERATIVE = '\n[solver]\nflow = "iterative"\nmechanics = "iterative"\nmonolithic = "iterative"\n'
DIRECT = '\n[solver]\nflow = "direct"\nmechanics = "direct"\nmonolithic = "direct"\n'
SCENES = [("default", "cantilever.geo", 2, "time.end=4.8"), ("block3d", "block3d.geo", 3, "time.end=0.6")]
CASES = [("split, direct", "C++", DIRECT, ()),
         ("split, iterative", "C++", ITERATIVE, ()),
         ("monolithic, direct", "C++", DIRECT, ("coupling.scheme=monolithic",)),
         ("monolithic, iterative", "C++", ITERATIVE, ("coupling.scheme=monolithic",)),
         ("split, direct", "prototype", DIRECT, ()),
         ("monolithic, direct", "prototype", DIRECT, ("coupling.scheme=monolithic",))]
for name, geo, d, end in SCENES:
    base_mesh, turned_mesh = meshes(geo, d)
    for label, track, extra, sets in CASES:
        base_out, _ = run_track(track, scene_on(name, base_mesh, d, False, extra), end, *sets)
        turned_out, _ = run_track(track, scene_on(name, turned_mesh, d, True, extra), end, *sets)
        compare(f"{name}, {label} ({track})", base_out, turned_out, d)
