"""A closed fault that nothing shears changes nothing (issue 37), on the C++
solver and the prototype: Terzaghi's column (uniaxial strain: rollers on the
sides, loaded on top, drained at the top) with a vertical fault in its middle,
x = 0 for 2 <= y <= 8, its tips inside the column. In uniaxial strain no
vertical plane carries shear and the horizontal stress is compressive, and the
flow is vertical: the fault stays closed, does not slip, and on a mesh
symmetric about x = 0 no discrete flow crosses it. So the run with the fault
gives the fields without it, node by node and cell by cell, to 1e-10:
mechanics alone, the split and the monolithic solve; the split equals the
monolithic solve, and Theorem 1's ratio, measured every iteration, is held
against gamma (a fault's deformable faces are outside the theorem's rigid
foundation; docs/verification.md records the ratio)."""
import os
import tempfile

import numpy as np
from support import Fields, check, max_difference, run_track, summary, unsplit_difference



def column_msh(nx=4, ny=40):
    """Gmsh's MSH 2.2 text of the column [-1, 1] x [0, 10] in nx x ny squares,
    each cut by a diagonal mirrored about x = 0 (the mesh is symmetric, so
    the discrete flow is too: no flux crosses x = 0), with the curve
    "fault" on x = 0 for 2 <= y <= 8 and the sides "left", "right",
    "bottom", "top"."""
    xs, ys = np.linspace(-1, 1, 2 * nx + 1), np.linspace(0, 10, ny + 1)
    node = lambda i, j: j * (2 * nx + 1) + i + 1  # noqa: E731
    lines, triangles = [], []
    for j in range(ny):
        for i in range(2 * nx):
            a, b, c, d = node(i, j), node(i + 1, j), node(i + 1, j + 1), node(i, j + 1)
            triangles += [(a, b, c), (a, c, d)] if i < nx else [(a, b, d), (b, c, d)]
    groups = {"bottom": 1, "right": 2, "top": 3, "left": 4, "fault": 5}
    lines += [(1, node(i, 0), node(i + 1, 0)) for i in range(2 * nx)]
    lines += [(2, node(2 * nx, j), node(2 * nx, j + 1)) for j in range(ny)]
    lines += [(3, node(i, ny), node(i + 1, ny)) for i in range(2 * nx)]
    lines += [(4, node(0, j), node(0, j + 1)) for j in range(ny)]
    lines += [(5, node(nx, j), node(nx, j + 1)) for j in range(ny) if 2 <= ys[j] and ys[j + 1] <= 8]
    text = ["$MeshFormat", "2.2 0 8", "$EndMeshFormat", "$PhysicalNames", str(len(groups) + 1)]
    text += [f'1 {tag} "{name}"' for name, tag in groups.items()] + ['2 6 "rock"', "$EndPhysicalNames", "$Nodes"]
    text += [str(len(xs) * len(ys))] + [f"{node(i, j)} {x!r} {y!r} 0" for j, y in enumerate(ys) for i, x in enumerate(xs)]
    text += ["$EndNodes", "$Elements", str(len(lines) + len(triangles))]
    text += [f"{k + 1} 1 2 {g} {g} {a} {b}" for k, (g, a, b) in enumerate(lines)]
    text += [f"{len(lines) + k + 1} 2 2 6 6 {a} {b} {c}" for k, (a, b, c) in enumerate(triangles)]
    return "\n".join(text + ["$EndElements", ""])


MECHANICS = """[mesh]
type = "gmsh"
file = "column.msh"
dimension = 2
[mechanics]
G = 3.0
lambda = 2.0
[time]
end = 0.2
dt = 0.02
[boundary.left]
displacement = { x = 0.0 }
[boundary.right]
displacement = { x = 0.0 }
[boundary.bottom]
displacement = { x = 0.0, y = 0.0 }
[boundary.top]
traction = [0.0, -1.0]
"""
FLOW = """pressure = 0.0
[flow]
M = 16.0
mu_f = 1.0
permeability = 1.5
[coupling]
alpha = 0.6
L = "paper"
tolerance = 1e-12
scheme = "{scheme}"
"""
FAULT = """[fault.fault]
normal = [1.0, 0.0]
"""


def scene(text):
    folder = tempfile.mkdtemp(prefix="scene-")
    with open(os.path.join(folder, "column.msh"), "w") as f:
        f.write(column_msh())
    with open(os.path.join(folder, "scene.toml"), "w") as f:
        f.write(text)
    return os.path.join(folder, "scene.toml")


CASES = {"mechanics": (MECHANICS, ["displacement"]),
         "fixed-stress": (MECHANICS + FLOW.format(scheme="fixed-stress"), ["displacement", "pressure"]),
         "monolithic": (MECHANICS + FLOW.format(scheme="monolithic"), ["displacement", "pressure"])}
for track in ("C++", "prototype"):
    runs = {}
    for case, (text, names) in CASES.items():
        with_fault, _ = run_track(track, scene(text + FAULT))
        runs[case] = with_fault
        without, _ = run_track(track, scene(text))
        worst = unsplit_difference(with_fault, without, names)
        check(max(worst.values()) <= 1e-10, f"{case} ({track}): the closed fault's run equals the run without it: "
              f"{worst} (limit 1e-10)")
        fields = Fields(with_fault)
        t = fields.times("contact_active")[-1]
        active = fields.at("contact_active", t)[:, 0]
        flag = fields.at("contact_boundary", fields.times("contact_boundary")[0])[:, 0]
        check(np.all(active[flag > 0.5] > 0.5), f"{case} ({track}): every pair of the fault in contact "
              f"({int(np.sum(active[flag > 0.5] > 0.5))} of {int(np.sum(flag > 0.5))})")
    differences = max_difference(runs["fixed-stress"], runs["monolithic"], ["displacement", "pressure"])
    check(max(differences.values()) <= 1e-9, f"fault scene ({track}): the split equals the monolithic solve: "
          f"{differences} (coupling tolerance 1e-12)")
    report = summary(runs["fixed-stress"])
    check(report["max_contraction_ratio"] <= report["gamma"] + 1e-12,
          f"fault scene ({track}): largest contraction ratio {report['max_contraction_ratio']:.4f} "
          f"<= gamma {report['gamma']:.4f}")
