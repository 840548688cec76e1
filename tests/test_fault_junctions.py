"""Contact where faults cross and end on one another (issue 52, verification
2; docs/theory.md, "Faults where they meet"), both tracks: an X and a T in a
4 m square. Under hydrostatic compression with friction 0.6 every pair
carries exactly the load (1e-10) and does not slip, in 2D and on two planes
crossing in a box (3D: a held side's slip bounded by 1e-6 of the
displacement, a finding); pressurised cracks open and converge under
refinement (order >= 0.5); sheared with friction in a coupled scene, split
= monolithic (1e-8, the same stick/slip states), 2 ranks = 1, a restart
ends equal (1e-12), prototype = C++ (1e-10); conduits opened by a gas, split
= monolithic (1e-8). Numbers: docs/verification.md, "What each test
verifies"."""
import os

import numpy as np
from support import (CROSS_GEO, PLANE_A, PLANE_B, check, compressed, fault_fields, gas_in_rigid_rock, gmsh_scene,
                     killed_and_restarted, max_difference, run_track, summary, written)
from test_fault_closure import fault_pressure_difference

GEO = """SetFactory("Built-in");
h = {h};
Point(1) = {{-2, -2, 0, 4 * h}}; Point(2) = {{2, -2, 0, 4 * h}}; Point(3) = {{2, 2, 0, 4 * h}};
Point(4) = {{-2, 2, 0, 4 * h}}; Point(5) = {{-1, 0, 0, h}}; Point(6) = {{0, 0, 0, h}}; Point(7) = {{1, 0, 0, h}};
Point(8) = {{0, -1, 0, h}}; Point(9) = {{0, 1, 0, h}}; Point(10) = {{0.5, 0, 0, h}}; Point(11) = {{0.5, 0.8, 0, h}};
Line(1) = {{1, 2}}; Line(2) = {{2, 3}}; Line(3) = {{3, 4}}; Line(4) = {{4, 1}};
Line(5) = {{5, 6}}; Line(6) = {{6, 10}}; Line(7) = {{10, 7}}; Line(8) = {{8, 6}}; Line(9) = {{6, 9}};
Line(10) = {{10, 11}};
Curve Loop(1) = {{1, 2, 3, 4}}; Plane Surface(1) = {{1}};
Curve{{5, 6, 7, 8, 9, 10}} In Surface{{1}};
Physical Curve("bottom") = {{1}}; Physical Curve("right") = {{2}}; Physical Curve("top") = {{3}};
Physical Curve("left") = {{4}}; Physical Curve("crack") = {{5, 6, 7}}; Physical Curve("other") = {{8, 9}};
Physical Curve("branch") = {{10}}; Physical Surface("rock") = {{1}};
"""
FAULTS = """[fault.crack]
normal = [0.0, 1.0]
{law}
[fault.other]
normal = [1.0, 0.0]
{law}
[fault.branch]
normal = [1.0, 0.0]
{law}
"""
HYDROSTATIC = compressed(1.0e6)
CLAMPED = "".join(f"[boundary.{side}]\ndisplacement = {{ x = 0.0, y = 0.0 }}\n"
                  for side in ("left", "bottom", "right", "top"))
COUPLED = """[mesh]
type = "gmsh"
file = "mesh.geo"
dimension = 2
[mechanics]
G = 3.0e9
lambda = 2.0e9
[flow]
M = 1.0e10
mu_f = 1.0e-3
permeability = 1.0e-12
initial_pressure = 0.0
[coupling]
alpha = 0.6
L = "paper"
tolerance = 1e-10
scheme = "fixed-stress"
[time]
end = 1.0
dt = 0.1
[boundary.left]
pressure = "4.0e6 * t"
displacement = { x = 0.0 }
[boundary.right]
pressure = 0.0
[boundary.bottom]
displacement = { x = 0.0, y = 0.0 }
[boundary.top]
traction = ["-3.0e6 * t", -1.0e7]
"""
# 3D: support's planes x = 1 and y = 1 across a 2 x 2 x 1 box, crossing along
# the line x = y = 1 from the bottom (z held there) to the top.
BOX = CROSS_GEO + PLANE_A + PLANE_B
BOX_HYDROSTATIC = """[fault.a]
normal = [1.0, 0.0, 0.0]
friction = 0.6
[fault.b]
normal = [0.0, 1.0, 0.0]
friction = 0.6
[boundary.left]
displacement = { x = 0.0 }
[boundary.front]
displacement = { y = 0.0 }
[boundary.bottom]
displacement = { z = 0.0 }
[boundary.right]
traction = [-1.0e6, 0.0, 0.0]
[boundary.back]
traction = [0.0, -1.0e6, 0.0]
[boundary.top]
traction = [0.0, 0.0, -1.0e6]
"""
# The three faults conduits of a gas (test_hydraulic_opening.py's), a well
# into the crack, the rock impermeable and decoupled, under 3 MPa.
CONDUITS = """[mesh]
type = "gmsh"
file = "mesh.geo"
dimension = 2
[mechanics]
E = 1.0e10
nu = 0.25
[time]
end = 1.0
dt = 0.25
""" + gas_in_rigid_rock(1.0e-7) + compressed(3.0e6) + """[well.inj]
fault = "crack"
position = [-0.5, 0.0]
rate = 2.0e-4
""" + FAULTS.format(law='flow = "conduit"\nresidual_aperture = 1.0e-4')
FIELDS = ["displacement", "pressure", "flux"]
CROSSING, T = np.array([0.0, 0.0]), np.array([0.5, 0.0])
TIPS = np.array([[-1.0, 0.0], [1.0, 0.0], [0.0, -1.0], [0.0, 1.0], [0.5, 0.8]])


def coupled_scene():
    path = written(COUPLED + FAULTS.format(law="friction = 0.6\npore_pressure_load = true"))
    with open(os.path.join(os.path.dirname(path), "mesh.geo"), "w") as f:
        f.write(GEO.format(h=0.1))
    return path


def at(points, where):
    return np.linalg.norm(points[:, :2] - where, axis=1) < 1e-12


def check_hydrostatic(track):
    """Every pair's traction is the 1 MPa of the load, at the X and the T too."""
    out, _ = run_track(track, gmsh_scene(GEO.format(h=0.1), FAULTS.format(law="friction = 0.6") + HYDROSTATIC))
    points, _, series = fault_fields(out, ("traction", "opening", "slip"))
    last = series[-1]
    paired = ~np.any([at(points, tip) for tip in TIPS], axis=0)  # a tip is one node: no pair
    error = np.abs(last["traction"][paired, 0] / 1.0e6 - 1).max()
    check(np.count_nonzero(at(points, CROSSING)) == 4 and np.count_nonzero(at(points, T)) == 3,
          f"{track}: four pairs at the X, three at the T")
    check(error <= 1e-10 and np.abs(last["opening"]).max() <= 1e-14 and np.abs(last["slip"]).max() <= 1e-14,
          f"{track}: every one of {np.count_nonzero(paired)} pairs, at the X and the T too, carries the 1 MPa of the "
          f"load (largest relative error {error:.1e}, 1e-10), closed and not slipping")


def check_crossing_planes(track):
    """3D: every pair of two planes crossing from a held bottom to the top,
    those along the crossing line too, carries the 1 MPa of the load."""
    out, _ = run_track(track, gmsh_scene(BOX, BOX_HYDROSTATIC, dimension=3))
    points, _, series = fault_fields(out, ("traction", "opening", "slip"))
    line = np.linalg.norm(points[:, :2] - 1.0, axis=1) < 1e-12
    last = series[-1]
    error = np.abs(last["traction"][:, 0] / 1.0e6 - 1).max()
    slip = np.abs(last["slip"]).max() / 1.0e-4  # of the largest displacement, 1e-4 m
    check(np.count_nonzero(line) > 0 and error <= 1e-10 and np.abs(last["opening"]).max() <= 1e-14 and slip <= 1e-6,
          f"{track}: 3D, every one of {len(points)} face nodes of two crossing planes ({np.count_nonzero(line)} on "
          f"the crossing line, z held at its foot) carries the 1 MPa of the load (largest relative error "
          f"{error:.1e}, 1e-10), closed, slip {slip:.1e} of the displacement (1e-6: where a plane meets a side "
          "with a held component)")


def check_pressurised(track):
    """The X's opening at the crossing and the cracks' mean opening under
    refinement."""
    measured = []
    for h in (0.2, 0.1, 0.05):
        out, _ = run_track(track, gmsh_scene(GEO.format(h=h), FAULTS.format(law='pressure = "1.0e6"') + CLAMPED))
        points, _, series = fault_fields(out, ("opening",))
        opening = series[-1]["opening"][:, 0]
        measured.append((opening[at(points, CROSSING)].mean(), summary(out)["contact"]["faults"]["crack"]))
    centre = [m[0] for m in measured]
    largest = [m[1]["max_opening"] for m in measured]
    orders = [np.log2(abs(a[1] - a[0]) / abs(a[2] - a[1])) for a in (centre, largest)]
    check(min(centre) > 0 and min(orders) >= 0.5,
          f"{track}: the X's opening at the crossing {['%.6e' % c for c in centre]} m and the crack's largest "
          f"{['%.6e' % c for c in largest]} m converge under refinement, observed orders {orders[0]:.2f}, "
          f"{orders[1]:.2f} (at least 0.5)")


def balance(out):
    """The largest imbalance of a fault's volumes with what crosses its
    intersections, of the volume injected."""
    volumes = summary(out)["fault_volumes"]
    return max(abs(v["injected"] + v["exchanged"] + v["intersections"] - v["stored"] - v["outflow"])
               for v in volumes.values()) / volumes["crack"]["injected"]


def check_conduits(track):
    """Conduits meeting under mechanics: closed and opening, the split =
    the monolithic solve; volumes balanced throughout."""
    path = written(CONDUITS)
    with open(os.path.join(os.path.dirname(path), "mesh.geo"), "w") as f:
        f.write(GEO.format(h=0.1))
    closed = [run_track(track, path, "time.end=0.5", *scheme)[0] for scheme in ((), ("coupling.scheme=monolithic",))]
    rates = {name: r["rate"] for name, r in summary(closed[0])["intersections"].items()}
    fields, p_f = max_difference(*closed, FIELDS), fault_pressure_difference(*closed)
    check(max(fields.values()) <= 1e-8 and p_f <= 1e-8 and max(map(balance, closed)) <= 1e-10
          and min(rates.values()) > 0,
          f"{track}: the closed network, the split against the monolithic solve: {fields}, p_f to {p_f:.1e} (1e-8); "
          f"volumes balanced to {max(map(balance, closed)):.1e} (1e-10), the fluid through the X and the T "
          f"({rates} m^2/s)")
    opened, _ = run_track(track, path, "coupling.scheme=monolithic")
    faults = summary(opened)["contact"]["faults"]
    widest = {name: f["max_opening"] for name, f in faults.items()}
    check(all(f["closed"] == 0 for f in faults.values()) and min(widest.values()) > 0 and balance(opened) <= 1e-10,
          f"{track}: the network opened by the gas (monolithic): every fault open, largest openings {widest} m, "
          f"volumes balanced to {balance(opened):.1e} (1e-10)")
    split, _ = run_track(track, path)
    fields, p_f = max_difference(split, opened, FIELDS), fault_pressure_difference(split, opened)
    # The split's volumes lag its last iterate's apertures by the coupling
    # tolerance: the bound every accepted step meets (1e-8), not 1e-10.
    check(max(fields.values()) <= 1e-8 and p_f <= 1e-8 and balance(split) <= 1e-8,
          f"{track}: the split through the network's opening (its crack's patch joined across the X and the T) "
          f"= the monolithic solve: {fields}, p_f to {p_f:.1e} (1e-8); volumes balanced to {balance(split):.1e} "
          "(1e-8)")
    return opened


def slip_states(out):
    return [f["state"][:, 0] for f in fault_fields(out, ("state",))[2]]


def check_coupled(track):
    """The T slipping under shear: split = monolithic, 2 ranks = 1, restart."""
    path = coupled_scene()
    split, _ = run_track(track, path)
    states = slip_states(split)
    check(max(np.count_nonzero(s == 2) for s in states) > 0 and max(np.count_nonzero(s == 1) for s in states) > 0,
          f"{track}: pairs slip and stick (slipping per output time "
          f"{[int(np.count_nonzero(s == 2)) for s in states]})")
    monolithic, _ = run_track(track, path, "coupling.scheme=monolithic")
    same = all(np.array_equal(a, b) for a, b in zip(states, slip_states(monolithic)))
    difference = max_difference(split, monolithic, FIELDS)
    check(same and max(difference.values()) <= 1e-8, f"{track}: the split equals the monolithic solve, the same "
          f"stick/slip states: {difference} (1e-8)")
    two, _ = run_track(track, path, ranks=2)
    ranks = max_difference(split, two, FIELDS, sort=True)
    check(max(ranks.values()) <= 1e-8, f"{track}: 2 ranks give 1 rank's fields: {ranks} (1e-8)")
    restarted, step = killed_and_restarted(track, path, 5)
    again = max_difference(split, restarted, FIELDS)
    check(max(again.values()) <= 1e-12, f"{track}: killed and restarted from step {step}: {again} (1e-12)")
    return split


runs = {}
for track in ("C++", "prototype"):
    check_hydrostatic(track)
    check_crossing_planes(track)
    check_pressurised(track)
    runs[track] = check_coupled(track)
    runs[track, "conduits"] = check_conduits(track)
tracks = max_difference(runs["C++"], runs["prototype"], FIELDS)
check(max(tracks.values()) <= 1e-10, f"the prototype equals the C++ solver: {tracks} (1e-10)")
conduits = fault_pressure_difference(runs["C++", "conduits"], runs["prototype", "conduits"])
check(conduits <= 1e-10, f"the opened network: the prototype's fault pressure is the C++ one's to {conduits:.1e} "
      "(1e-10)")
