"""Tips graded by the project (issue 53, item 3), on the C++ solver and the
prototype: Sneddon's pressurised crack (scenes/sneddon_near.toml) on the
uniform mesh meshes/sneddon2d_uniform.geo (cells of 0.1 m), with and without
fault.crack.tip_size = 2 mm (tip_grading 0.3):
- the graded mesh's cells at each tip are at most 2 tip_size across, the
  uniform mesh's at least 20 times that;
- the opening's l2 error against Sneddon's ellipse (the tips' 10 % excluded)
  falls 5x with the grading, and under refinement at order >= 1.5 graded,
  below 1.2 uniform; the prototype's graded mesh gives the C++ opening (1e-10);
- 3D (C++): a disc crack's rim nodes at most 1.5 tip_size apart;
- a crack from boundary to boundary has no tip to grade: exit 2, one line."""
import math
import os

import h5py
import numpy as np
from support import Fields, check, gmsh_scene, run_track, scene

E, NU, P, A = 1.0e10, 0.25, 1.0e6, 1.0
DIRECTION = np.array([math.cos(math.pi / 6), math.sin(math.pi / 6)])
TIP, GRADING = 0.002, 0.3
UNIFORM = "mesh.file=sneddon2d_uniform.geo"
GRADED = (UNIFORM, f"fault.crack.tip_size={TIP}", f"fault.crack.tip_grading={GRADING}")


def opening(out):
    """The last opening at fault.xdmf's nodes, by their distance s along the crack."""
    with h5py.File(os.path.join(out, "fault.h5")) as f:
        x = f["Mesh/geometry"][:, :2]
        values = f[f"opening/{max(int(k) for k in f['opening'].keys())}"][:].reshape(-1)
    s = x @ DIRECTION
    order = np.argsort(s)
    return s[order], values[order]


def error(out):
    """The opening's relative l2 error over the inner 90 % of each half."""
    s, w = opening(out)
    exact = 4 * (1 - NU ** 2) * P / E * np.sqrt(np.maximum(A ** 2 - s ** 2, 0.0))
    inner, length = np.abs(s) <= 0.9 * A, np.abs(np.gradient(s))
    return math.sqrt(np.sum(length[inner] * (w - exact)[inner] ** 2) / np.sum(length[inner] * exact[inner] ** 2))


def tip_cell_size(out):
    """The longest edge of the cells that touch either tip."""
    fields = Fields(out)
    x, cells = fields.nodes[:, :2], fields.topology
    largest = 0.0
    for tip in (A * DIRECTION, -A * DIRECTION):
        at = np.flatnonzero(np.linalg.norm(x - tip, axis=1) < 1e-9)
        for cell in cells[np.isin(cells, at).any(axis=1)]:
            largest = max(largest, max(np.linalg.norm(x[i] - x[j]) for i in cell for j in cell))
    return largest


runs = {}
for track in ("C++", "prototype"):
    runs[track], _ = run_track(track, scene("sneddon_near"), *GRADED)
    size = tip_cell_size(runs[track])
    check(size <= 2 * TIP, f"{track}: the graded mesh's cells at the tips are {size:.2e} m across "
          f"(at most 2 tip_size = {2 * TIP:g}: gmsh's size is an edge length, grown by the grading one cell out)")
s_cpp, w_cpp = opening(runs["C++"])
s_py, w_py = opening(runs["prototype"])
d = np.abs(w_cpp - w_py).max() / np.abs(w_cpp).max() if len(w_cpp) == len(w_py) else math.inf
check(d <= 1e-10, f"prototype = C++ on the graded mesh: the opening to {d:.1e} (1e-10)")

errors = {}
for label, sets in (("uniform", (UNIFORM,)), ("graded", GRADED)):
    for refine in (0, 1):
        out = runs["C++"] if (label, refine) == ("graded", 0) else run_track("C++", scene("sneddon_near"), *sets,
                                                                            f"mesh.refine={refine}")[0]
        errors[label, refine] = error(out)
        if (label, refine) == ("uniform", 0):
            size = tip_cell_size(out)
            check(size >= 20 * TIP, f"the uniform mesh's cells at the tips are {size:.2e} m across")
order = {label: math.log2(errors[label, 0] / errors[label, 1]) for label in ("uniform", "graded")}
check(errors["graded", 0] * 5 <= errors["uniform", 0],
      f"the grading takes the opening error from {errors['uniform', 0]:.2e} to {errors['graded', 0]:.2e} (at least 5x)")
check(order["graded"] >= 1.5 and order["uniform"] < 1.2,
      f"observed order from refine 0 to 1: {order['graded']:.2f} graded (at least 1.5), {order['uniform']:.2f} "
      f"uniform (below 1.2); errors {errors['graded', 1]:.2e} and {errors['uniform', 1]:.2e} at refine 1")

# 3D: a disc crack of radius 1 m in a box of 4 m (OpenCASCADE fragments), its
# rim the tip curve: the C++ run's rim nodes at most 1.5 tip_size apart.
DISC_GEO = """SetFactory("OpenCASCADE");
Box(1) = {-2, -2, -2, 4, 4, 4};
Disk(100) = {0, 0, 0, 1};
BooleanFragments{ Volume{1}; Delete; }{ Surface{100}; Delete; }
Physical Surface("crack") = {100}; Physical Surface("bottom") = {105}; Physical Surface("top") = {103};
Physical Volume("rock") = {1};
Mesh.CharacteristicLengthMax = 0.5;
"""
DISC = """[boundary.bottom]
displacement = { x = 0.0, y = 0.0, z = 0.0 }
[boundary.top]
displacement = { x = 0.0, y = 0.0, z = 0.0 }
[fault.crack]
pressure = "1.0e6"
normal = [0.0, 0.0, 1.0]
tip_size = 0.1
"""
out, _ = run_track("C++", gmsh_scene(DISC_GEO, DISC, dimension=3))
fields = Fields(out)
x, cells = fields.nodes, fields.topology
rim = np.flatnonzero((np.abs(np.linalg.norm(x[:, :2], axis=1) - 1.0) < 1e-6) & (np.abs(x[:, 2]) < 1e-9))
spacing = 2 * math.pi / max(len(rim), 1)
check(spacing <= 1.5 * 0.1, f"3D: the disc's rim holds {len(rim)} nodes, {spacing:.3f} m apart (at most 1.5 "
      "tip_size = 0.15; the mesh's 0.5 elsewhere)")

# A crack from side to side: no tip inside the body.
THROUGH_GEO = """SetFactory("Built-in");
Point(1) = {0, 0, 0, 0.1}; Point(2) = {1, 0, 0, 0.1}; Point(3) = {1, 1, 0, 0.1}; Point(4) = {0, 1, 0, 0.1};
Point(5) = {0, 0.5, 0, 0.1}; Point(6) = {1, 0.5, 0, 0.1};
Line(1) = {1, 2}; Line(2) = {2, 6}; Line(3) = {6, 3}; Line(4) = {3, 4}; Line(5) = {4, 5}; Line(6) = {5, 1};
Line(7) = {5, 6};
Curve Loop(1) = {1, 2, 3, 4, 5, 6}; Plane Surface(1) = {1};
Curve{7} In Surface{1};
Physical Curve("bottom") = {1}; Physical Curve("top") = {4}; Physical Curve("cut") = {7};
Physical Surface("rock") = {1};
"""
THROUGH = """[boundary.bottom]
displacement = { x = 0.0, y = 0.0 }
[boundary.top]
displacement = { x = 0.0, y = -1.0e-4 }
[fault.cut]
normal = [0.0, 1.0]
tip_size = 0.01
"""
path = gmsh_scene(THROUGH_GEO, THROUGH)
for track in ("C++", "prototype"):
    out, p = run_track(track, path, expect=2)
    lines = p.stderr.strip().splitlines()
    check(len(lines) == 1 and "fault.cut.tip_size: the fault has no tip inside the body" in lines[0],
          f"{track}: a crack from side to side with tip_size: {lines[-1][:150] if lines else ''!r}")
