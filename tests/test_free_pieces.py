"""A body that nothing holds (issue 50, item 4), both tracks: a square cut in two
by a frictionless fault from side to side, its bottom clamped and its top
loaded (down and sideways, or down only), ran with exit 0 and a slip of 4e10 m
(down only: the upper block drifted sideways as a rigid body). Now `check` and
`run` refuse it in one line naming the fault, the side and a point of the free
piece, exit 2, nothing written. What holds it is accepted and runs: friction on
the fault (mu = 0.6: every pair stuck, the slip below 1e-12 m), or a roller on
the left side (the slip then the elastic one, below 1e-4 m, on either contact
path: the full path's first step from the unloaded start presses on nothing,
its reduced system is singular, and a residual 9x the first was once accepted
as converged, with a slip of 2.6e-3 m). The pieces and the rank of their held
rigid motions are unit-tested in tests/unit/test_pieces.*."""
import os

from support import ROOT, TRACKS, check, run_track, summary, written
import subprocess

CUT_GEO = """h = 0.1;
Point(1) = {0, 0, 0, h}; Point(2) = {1, 0, 0, h}; Point(3) = {1, 0.5, 0, h}; Point(4) = {1, 1, 0, h};
Point(5) = {0, 1, 0, h}; Point(6) = {0, 0.5, 0, h};
Line(1) = {1, 2}; Line(2) = {2, 3}; Line(3) = {3, 4}; Line(4) = {4, 5}; Line(5) = {5, 6}; Line(6) = {6, 1};
Line(7) = {6, 3};
Curve Loop(1) = {1, 2, -7, 6}; Plane Surface(1) = {1};
Curve Loop(2) = {7, 3, 4, 5}; Plane Surface(2) = {2};
Physical Curve("bottom") = {1}; Physical Curve("top") = {4};
Physical Curve("left") = {5, 6}; Physical Curve("right") = {2, 3};
Physical Curve("cut") = {7};
Physical Surface("rock") = {1, 2};
"""
SCENE = """[scene]
name = "cut"
[mesh]
type = "gmsh"
file = "cut.geo"
dimension = 2
[mechanics]
E = 1.0e9
nu = 0.25
[time]
end = 1.0
dt = 1.0
[fault.cut]
normal = [0.0, 1.0]
[boundary.bottom]
clamp = true
[boundary.top]
traction = [{shear}, -1.0e6]
"""


def cut_scene(shear):
    path = written(SCENE.format(shear=shear))
    with open(os.path.join(os.path.dirname(path), "cut.geo"), "w") as f:
        f.write(CUT_GEO)
    return path


def check_refused(track, path, label):
    for command in ("check", "run"):
        out = os.path.join(os.path.dirname(path), f"out-{command}")
        p = subprocess.run([*TRACKS[track], command, path, "--out", out], capture_output=True, text=True, cwd=ROOT,
                           timeout=300)
        lines = p.stderr.strip().splitlines()
        check(p.returncode == 2 and len(lines) == 1 and "fault.cut: the piece on its + side (its node at (0.000000, "
              "0.500000)) is free to move as a rigid body" in lines[0] and not os.path.exists(out),
              f"{track}: {label}: {command} exits 2 in one line, nothing written: {lines[-1][:160]!r}")


def check_held(track, path, label, sets, largest, options=()):
    out, _ = run_track(track, path, *sets, options=options)
    slip = summary(out)["contact"]["faults"]["cut"]["max_slip"]
    check(slip <= largest, f"{track}: {label}: runs, the largest slip {slip:.3e} m (at most {largest:g})")


for track in ("C++", "prototype"):
    for shear, label in ((1.0e5, "pushed down and sideways"), (0.0, "pushed down only")):
        check_refused(track, cut_scene(shear), label)
    check_held(track, cut_scene(1.0e5), "friction 0.6", ("fault.cut.friction=0.6",), 1e-12)
    for path in ("true", "false"):
        check_held(track, cut_scene(0.0), f"a roller on the left, condensed {path}",
                   ("boundary.left.displacement={ x = 0.0 }",), 1e-4, ("-mechanics_contact_condensed", path))
