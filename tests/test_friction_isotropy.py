"""Friction in 3D is isotropic (issue 38), both tracks: a penny crack in a
cube, pressed and sheared, mu = 0.3, slipping held by friction. At every
slipping pair |t_T| = mu t_N (1e-9) along the slip (1e-7 rad: a polygon, or
a stiffness per tangential unknown, would not); the scene turned by 30
degrees about the normal slips by the turned slip (1e-8; the pairs' frames
do not turn); the iterative full path gives the direct one's slip (1e-8)
with fewer preconditioner set-ups than Newton steps; the direct full path
factorises fewer times than it takes Newton steps (an earlier
factorisation preconditions GMRES; with preonly and on the condensed path
the same slip, 1e-10) and goes on factorising where GMRES fails; the
prototype = C++ (1e-10). Numbers: docs/verification.md."""
import json
import math
import os
import subprocess

import numpy as np
from support import check, fault_fields, max_difference, run_track, written

GEO = """SetFactory("OpenCASCADE");
a = 1;
L = 4;
Box(1) = {-L, -L, -L, 2 * L, 2 * L, 2 * L};
Disk(100) = {0, 0, 0, a};
BooleanFragments{ Volume{1}; Delete; }{ Surface{100}; Delete; }
e = 1e-6;
Physical Surface("crack") = {Surface In BoundingBox{-a - e, -a - e, -e, a + e, a + e, e}};
Physical Surface("bottom") = {Surface In BoundingBox{-L - e, -L - e, -L - e, L + e, L + e, -L + e}};
Physical Surface("top") = {Surface In BoundingBox{-L - e, -L - e, L - e, L + e, L + e, L + e}};
Physical Volume("rock") = {Volume{:}};
Field[1] = MathEval;
Field[1].F = Sprintf("0.12 + 0.25 * Sqrt(Max(Sqrt(x^2 + y^2) - %g, 0)^2 + z^2)", a);
Background Field = 1;
Mesh.CharacteristicLengthExtendFromBoundary = 0;
Mesh.CharacteristicLengthFromPoints = 0;
Mesh.CharacteristicLengthFromCurvature = 0;
"""
MU, SHEAR, PRESSURE, TURN = 0.3, 2.0e7, 5.0e7, math.pi / 6
ROTATION = np.array([[math.cos(TURN), -math.sin(TURN), 0.0], [math.sin(TURN), math.cos(TURN), 0.0], [0.0, 0.0, 1.0]])
SCENE = """[mesh]
type = "gmsh"
file = "{mesh}"
dimension = 3
[mechanics]
E = 25.0e9
nu = 0.25
[time]
end = 1.0
dt = 1.0
[solver]
mechanics = "direct"
[boundary.bottom]
displacement = {{ x = 0.0, y = 0.0, z = 0.0 }}
[boundary.top]
traction = [{tx!r}, {ty!r}, {tz!r}]
[fault.crack]
friction = {mu}
normal = [0.0, 0.0, 1.0]
"""


def meshes():
    """penny.msh (gmsh, MSH 2.2) and turned.msh, its nodes turned by TURN
    about z, in one folder."""
    folder = os.path.dirname(written(""))
    with open(os.path.join(folder, "penny.geo"), "w") as f:
        f.write(GEO)
    mesh = os.path.join(folder, "penny.msh")
    p = subprocess.run(["gmsh", "-3", os.path.join(folder, "penny.geo"), "-format", "msh22", "-o", mesh],
                       capture_output=True, text=True)
    check(p.returncode == 0, f"gmsh meshes the penny-shaped crack ({p.stderr.strip()[-200:]!r})")
    with open(mesh) as f:
        lines = f.read().split("\n")
    first = lines.index("$Nodes") + 2
    for k in range(first, first + int(lines[first - 1])):
        tag, *x = lines[k].split()
        turned = ROTATION @ np.array([float(v) for v in x])
        lines[k] = " ".join([tag] + [repr(float(v)) for v in turned])
    with open(os.path.join(folder, "turned.msh"), "w") as f:
        f.write("\n".join(lines))
    return folder


def scene(folder, mesh, shear):
    path = os.path.join(folder, mesh.replace(".msh", ".toml"))
    with open(path, "w") as f:
        f.write(SCENE.format(mesh=mesh, tx=shear[0], ty=shear[1], tz=-PRESSURE, mu=MU))
    return path


def check_disc(out, track):
    _, _, series = fault_fields(out)
    f = series[-1]
    slipping = f["state"][:, 0] == 2
    t_n, t_t, slip = f["traction"][slipping, 0], f["tangential_traction"][slipping], f["slip"][slipping]
    on_bound = np.abs(np.linalg.norm(t_t, axis=1) / (MU * t_n) - 1).max()
    check(slipping.sum() > 10 and on_bound <= 1e-9, f"{track}: at every one of the {slipping.sum()} slipping "
          f"pairs |t_T| = mu t_N to {on_bound:.1e} (1e-9)")
    cosine = np.sum(t_t * slip, axis=1) / (np.linalg.norm(t_t, axis=1) * np.linalg.norm(slip, axis=1))
    angle = np.arccos(np.clip(cosine, -1, 1)).max()
    check(angle <= 1e-7, f"{track}: the tangential traction points along the slip to {angle:.1e} rad (1e-7)")


def check_iterative(folder, track, direct):
    out, _ = run_track(track, os.path.join(folder, "penny.toml"), 'solver.mechanics="iterative"')
    with open(os.path.join(out, "summary.json")) as f:
        solver = json.load(f)["solvers"]["mechanics"]
    a, b = fault_fields(direct)[2][-1]["slip"], fault_fields(out)[2][-1]["slip"]
    scale = np.linalg.norm(a, axis=1).max()
    same = np.abs(a - b).max() / scale
    setups, steps = solver["preconditioner_setups"], solver["newton_iterations"]
    check(same <= 1e-8 and setups < steps, f"{track}: the iterative path slips as the direct one to {same:.1e} (1e-8), "
          f"its preconditioner set up {setups} times in {steps} Newton steps (fewer)")


def check_reused_factorization(folder, track, direct):
    """The full path on the factorised whole system: the slipping pairs'
    rows of the Jacobian turn at every Newton step, and the factorisation
    of an earlier one preconditions GMRES; with -mechanics_ksp_type preonly
    given, every changed Jacobian is factorised."""
    full = ["-mechanics_contact_condensed", "false"]
    reused, _ = run_track(track, os.path.join(folder, "penny.toml"), options=full)
    each, _ = run_track(track, os.path.join(folder, "penny.toml"), options=full + ["-mechanics_ksp_type", "preonly"])
    # One GMRES iteration: it fails on an earlier factorisation, and the
    # solve goes on factorising each new Jacobian.
    failing, _ = run_track(track, os.path.join(folder, "penny.toml"), options=full + ["-mechanics_ksp_max_it", "1"])
    a, b, c = (json.load(open(os.path.join(out, "summary.json")))["solvers"]["mechanics"]
               for out in (reused, each, failing))
    check("gmres on the last factorisation" in a["method"] and a["factorizations"] < a["newton_iterations"]
          and b["factorizations"] == b["newton_iterations"] == a["newton_iterations"],
          f"{track}: the full path factorises {a['factorizations']} times in {a['newton_iterations']} Newton steps "
          f"(GMRES on the last factorisation, {a['linear_iterations']} iterations), {b['factorizations']} times with "
          f"-mechanics_ksp_type preonly")
    check(c["factorizations"] > a["factorizations"], f"{track}: with -mechanics_ksp_max_it 1 GMRES fails on the "
          f"earlier factorisation and the solve goes on factorising ({c['factorizations']} factorisations, "
          f"{c['newton_iterations']} Newton steps)")
    d = max(max_difference(reused, other, ["displacement"])["displacement"] for other in (each, failing, direct))
    check(d <= 1e-10, f"{track}: its displacement is the one of a factorisation per Jacobian, of the failed GMRES "
          f"and of the condensed path to {d:.1e} (1e-10)")


folder = meshes()
runs = {}
for track in ("C++", "prototype"):
    straight, _ = run_track(track, scene(folder, "penny.msh", [SHEAR, 0.0]))
    turned, _ = run_track(track, scene(folder, "turned.msh", list(ROTATION[:2, :2] @ [SHEAR, 0.0])))
    check_disc(straight, track)
    xa, _, a = fault_fields(straight)
    xb, _, b = fault_fields(turned)
    index = {tuple(np.round(x, 7)): i for i, x in enumerate(xb)}
    matched = np.array([index[tuple(np.round(ROTATION @ x, 7))] for x in xa])
    slip_a, slip_b = a[-1]["slip"], b[-1]["slip"][matched]
    scale = np.linalg.norm(slip_a, axis=1).max()
    turned_by = np.abs(slip_b - slip_a @ ROTATION.T).max() / scale
    lengths = np.abs(np.linalg.norm(slip_b, axis=1) - np.linalg.norm(slip_a, axis=1)).max() / scale
    check(turned_by <= 1e-8 and lengths <= 1e-8, f"{track}: turned by 30 degrees, the slip vectors turn with it to "
          f"{turned_by:.1e}, their lengths unchanged to {lengths:.1e} (1e-8; largest slip {scale:.4e} m)")
    runs[track] = straight
    check_iterative(folder, track, straight)
    check_reused_factorization(folder, track, straight)
tracks = max_difference(runs["C++"], runs["prototype"], ["displacement"])
check(tracks["displacement"] <= 1e-10, f"the prototype equals the C++ solver: {tracks} (1e-10)")
