"""Flow through a network of conduit faults (docs/theory.md, "Flow in a fault
network"), both tracks. Rigid impermeable rock: every fault cell's pressure and
the rate through each intersection equal the resistor network's (cubic-law
conductances, Kirchhoff at an X, a T and four faults through one point; also
with finite normal permeabilities) to 1e-10; each fault balances with its
intersections, in 2D and on two planes crossing in 3D, where one plane drawn as
one or two groups gives the same pressure; 2 ranks = 1 and a restart ends equal
on a transient network; the shipped scenes/network2d.toml and network3d.toml
spread the injected fluid through their intersections, balanced, every pair
within the Coulomb disc; the star under mechanics (friction, a well) opens,
slips and sticks, balanced, 2 ranks = 1, and fed faster passes its first step
halved. Numbers: docs/verification.md, "What each test verifies"."""
import os
import subprocess

import h5py
import numpy as np
from support import (CROSS_GEO, MPI_ENV, PLANE_A, PLANE_B, ROOT, TRACKS, check, fault_centroids, iterations,
                     killed_and_restarted, max_difference, run_track, summary, written)
from support import scene as shipped

MU = 1.0e-3
APERTURES = {"a": 1.0e-4, "b": 2.0e-4, "c": 1.5e-4}
NETWORK_GEO = """SetFactory("Built-in");
h = 0.125;
Point(1) = {0, 0, 0, h}; Point(2) = {4, 0, 0, h}; Point(3) = {4, 2, 0, h}; Point(4) = {0, 2, 0, h};
Point(5) = {0, 1, 0, h}; Point(6) = {4, 1, 0, h}; Point(7) = {2, 0, 0, h}; Point(8) = {2, 2, 0, h};
Point(9) = {1, 2, 0, h}; Point(10) = {1, 1, 0, h}; Point(11) = {2, 1, 0, h};
Line(1) = {1, 7}; Line(2) = {7, 2}; Line(3) = {2, 6}; Line(4) = {6, 3}; Line(5) = {3, 8}; Line(6) = {8, 9};
Line(7) = {9, 4}; Line(8) = {4, 5}; Line(9) = {5, 1};
Line(10) = {5, 10}; Line(11) = {10, 11}; Line(12) = {11, 6}; Line(13) = {7, 11}; Line(14) = {11, 8};
Line(15) = {10, 9};
Curve Loop(1) = {1, 2, 3, 4, 5, 6, 7, 8, 9}; Plane Surface(1) = {1};
Line{10, 11, 12, 13, 14, 15} In Surface{1};
Physical Curve("bottom") = {1, 2}; Physical Curve("right") = {3, 4}; Physical Curve("top") = {5, 6, 7};
Physical Curve("left") = {8, 9}; Physical Curve("a") = {10, 11, 12}; Physical Curve("b") = {13, 14};
Physical Curve("c") = {15}; Physical Surface("rock") = {1};
"""
PLANE_A_HALVES = ('Physical Surface("a1") = Surface In BoundingBox{1 - e, -e, -e, 1 + e, 1 + e, 1 + e};\n'
                  'Physical Surface("a2") = Surface In BoundingBox{1 - e, 1 - e, -e, 1 + e, 2 + e, 1 + e};\n')
FLOW = """[flow]
mu_f = 1.0e-3
permeability = 1.0e-25
c_f = 0.0
initial_pressure = 1.0e6
[time]
end = 1.0
dt = 1.0
"""


def conduit(name, w, normal):
    return f'[fault.{name}]\nflow = "conduit"\nresidual_aperture = {w}\nnormal = {normal}\n'


def scene(geo, dimension, text):
    path = written(f'[mesh]\ntype = "gmsh"\nfile = "mesh.geo"\ndimension = {dimension}\n' + FLOW + text)
    with open(os.path.join(os.path.dirname(path), "mesh.geo"), "w") as f:
        f.write(geo)
    return path


def fault_pressure(out):
    """fault.xdmf's cells: centroids, fault ids and the last pressure."""
    with h5py.File(os.path.join(out, "fault.h5")) as f:
        return fault_centroids(out), f["Mesh/fault"][:].ravel().astype(int), f[f"pressure/{len(f['pressure']) - 1}"][:, 0]


# The network's segments: (fault id, from, to, the coordinate along it at
# each end); ends "left" .. "bottom" held, "T" (1, 1) and "X" (2, 1) free.
SEGMENTS = [(0, "left", "T", 0.0, 1.0), (0, "T", "X", 1.0, 2.0), (0, "X", "right", 2.0, 4.0),
            (1, "bottom", "X", 0.0, 1.0), (1, "X", "top", 1.0, 2.0), (2, "T", "top", 1.0, 2.0)]
HELD = {"left": 3e6, "right": 1e6, "top": 2e6, "bottom": 0.5e6}
MEETING = {"T": ("a", "c"), "X": ("a", "b")}


def resistor_network(normal_permeability):
    """The pressures at the T and the X and each fault's exact profile
    (fault ids in alphabetical order: a, b, c): cubic-law conductances
    along the segments, and at each intersection the series resistance
    r_j = mean of mu_f / (2 k_n) over the faults that meet there."""
    t = [w ** 3 / (12 * MU) for w in APERTURES.values()]
    r = {j: np.mean([MU / (2 * normal_permeability.get(f, np.inf)) for f in faults]) for j, faults in MEETING.items()}
    r.update({end: 0.0 for end in HELD})
    conductance = [1 / ((b - a) / t[f] + r[m] + r[n]) for f, m, n, a, b in SEGMENTS]
    free = list(MEETING)
    A, rhs = np.zeros((2, 2)), np.zeros(2)
    for g, (_, m, n, _, _) in zip(conductance, SEGMENTS):  # Kirchhoff's current law at T and X
        for here, there in ((m, n), (n, m)):
            if here in free:
                A[free.index(here), free.index(here)] += g
                if there in free:
                    A[free.index(here), free.index(there)] -= g
                else:
                    rhs[free.index(here)] += g * HELD[there]
    p = dict(HELD, **dict(zip(free, np.linalg.solve(A, rhs))))
    # What passes through each intersection: the inflows of its segments.
    through = {j: sum(max(g * (p[n if m == j else m] - p[j]), 0.0) for g, (_, m, n, _, _) in zip(conductance, SEGMENTS)
                      if j in (m, n)) for j in free}
    pieces = {0: ([], []), 1: ([], []), 2: ([], [])}  # per fault: coordinates and pressures at the segments' ends
    for g, (f, m, n, a, b) in zip(conductance, SEGMENTS):
        F = g * (p[m] - p[n])
        pieces[f][0].extend([a, b])
        pieces[f][1].extend([p[m] - F * r[m], p[n] + F * r[n]])

    def profile(f, x, y):
        coordinates, values = pieces[f]
        s = x if f == 0 else y
        k = min(range(0, len(coordinates), 2), key=lambda k: 0 if coordinates[k] <= s <= coordinates[k + 1] else 1)
        return np.interp(s, coordinates[k:k + 2], values[k:k + 2])
    return p["T"], p["X"], profile, through


def imbalance(v):
    """A fault's volume imbalance: injected + exchanged + intersections -
    stored - outflow."""
    return abs(v["injected"] + v["exchanged"] + v["intersections"] - v["stored"] - v["outflow"])


def contact_history(out):
    """fault.h5's normal and tangential traction, opening, slip and state
    at every pair (rows: the output times in order)."""
    with h5py.File(os.path.join(out, "fault.h5")) as f:
        times = sorted(f["traction"], key=int)
        return {"sigma": np.array([f[f"traction/{t}"][:, 0] for t in times]),
                "tau": np.array([np.linalg.norm(f[f"tangential_traction/{t}"][:], axis=1) for t in times]),
                "opening": np.array([f[f"opening/{t}"][:, 0] for t in times]),
                "slip": np.array([np.linalg.norm(f[f"slip/{t}"][:], axis=1) for t in times]),
                "state": np.array([f[f"state/{t}"][:, 0] for t in times])}


def check_volumes(out, track, label):
    """Each fault balanced with its intersections, which sum to zero."""
    volumes = summary(out)["fault_volumes"]
    scale = max(abs(v) for f in volumes.values() for v in f.values())
    worst = max(imbalance(v) for v in volumes.values()) / scale
    total = abs(sum(v["intersections"] for v in volumes.values())) / scale
    crossing = min(abs(v["intersections"]) for v in volumes.values()) / scale
    check(worst <= 1e-10 and total <= 1e-12 and crossing > 1e-3,
          f"{track}, {label}: each fault's volumes balance with its intersections to {worst:.1e} (1e-10), the "
          f"intersections sum to {total:.1e} over the faults (1e-12); each fault exchanges {crossing:.2f} of the "
          "largest volume through them")


def check_kirchhoff(track, normal_permeability):
    faults = "".join(conduit(name, w, normal) + (f"normal_permeability = {normal_permeability[name]}\n"
                                                 if name in normal_permeability else "")
                     for (name, w), normal in zip(APERTURES.items(), ("[0.0, 1.0]", "[1.0, 0.0]", "[1.0, 0.0]")))
    boundaries = "".join(f"[boundary.{b}]\npressure = {p}\n" for b, p in HELD.items())
    out_scene = scene(NETWORK_GEO, 2, boundaries + faults)
    out, _ = run_track(track, out_scene)
    x, ids, p = fault_pressure(out)
    p_t, p_x, profile, through = resistor_network(normal_permeability)
    exact = np.array([profile(i, *c[:2]) for i, c in zip(ids, x)])
    error = np.abs(p - exact).max() / 3e6
    label = "k_n = inf" if not normal_permeability else f"k_n {normal_permeability}"
    check(error <= 1e-10 and sorted(set(ids.tolist())) == [0, 1, 2],
          f"{track}: Kirchhoff ({label}), the T at {p_t / 1e6:.6f} MPa and the X at {p_x / 1e6:.6f} MPa; every cell "
          f"of the three faults ({len(p)}) on the resistor network's profile to {error:.1e} (1e-10)")
    rates = summary(out)["intersections"]
    off = {j: rates[" & ".join(MEETING[j])]["rate"] / through[j] - 1 for j in MEETING}
    check(sorted(rates) == ["a & b", "a & c"] and all(r["junctions"] == 1 for r in rates.values())
          and max(abs(e) for e in off.values()) <= 1e-10,
          f"{track}: Kirchhoff ({label}), the summary's rate through the T and the X, "
          f"{rates['a & c']['rate']:.6e} and {rates['a & b']['rate']:.6e} m^2/s, the resistor network's to "
          f"{max(abs(e) for e in off.values()):.1e} (1e-10)")
    check_volumes(out, track, f"2D, {label}")
    if track == "C++" and not normal_permeability:
        check_ranks_and_restart(out_scene)
    return out


def check_ranks_and_restart(scene_file):
    transient = ("flow.c_f=1.0e-9", "time.end=0.01", "time.dt=2.5e-4")
    one, _ = run_track("C++", scene_file, *transient)
    two, _ = run_track("C++", scene_file, *transient, ranks=2)
    restarted, step = killed_and_restarted("C++", scene_file, 20, *transient)
    def by_centroid(out):
        x, _, p = fault_pressure(out)
        return p[np.lexsort(x.T)]
    p = by_centroid(one)
    for label, other in (("2 ranks", two), (f"restarted at step {step}", restarted)):
        d = np.abs(by_centroid(other) - p).max() / np.abs(p).max()
        a, b = summary(one)["fault_volumes"], summary(other)["fault_volumes"]
        volumes = max(abs(a[f][k] - b[f][k]) for f in a for k in a[f]) / max(abs(v) for f in a for v in a[f].values())
        a, b = summary(one)["intersections"], summary(other)["intersections"]
        rates = max(abs(a[j]["rate"] / b[j]["rate"] - 1) for j in a) if sorted(a) == sorted(b) else np.inf
        check(d <= 1e-12 and volumes <= 1e-12 and rates <= 1e-12 and step < 40, f"C++, the transient network, "
              f"{label}: the same fault pressure ({d:.1e}), volumes, intersections included ({volumes:.1e}), and "
              f"rates through the intersections ({rates:.1e}) (1e-12)")


def check_crossing_planes(track):
    boundaries = "".join(f"[boundary.{b}]\npressure = {p}\n"
                         for b, p in (("left", 1.8e6), ("right", 1.2e6), ("front", 2e6), ("back", 1e6)))
    out, _ = run_track(track, scene(CROSS_GEO + PLANE_A + PLANE_B, 3, boundaries + conduit(
        "a", 1.0e-4, "[1.0, 0.0, 0.0]") + conduit("b", 2.0e-4, "[0.0, 1.0, 0.0]")))
    check_volumes(out, track, "3D crossing planes")
    if track != "C++":
        return out
    whole, _ = run_track(track, scene(CROSS_GEO + PLANE_A, 3, boundaries + conduit(
        "a", 1.0e-4, "[1.0, 0.0, 0.0]")))
    halves, _ = run_track(track, scene(CROSS_GEO + PLANE_A_HALVES, 3, boundaries + conduit(
        "a1", 1.0e-4, "[1.0, 0.0, 0.0]") + conduit("a2", 1.0e-4, "[1.0, 0.0, 0.0]")))
    (x1, _, p1), (x2, _, p2) = fault_pressure(whole), fault_pressure(halves)
    o1, o2 = np.lexsort(x1.T), np.lexsort(x2.T)
    same = np.allclose(x1[o1], x2[o2], rtol=0, atol=1e-12)
    d = np.abs(p1[o1] - p2[o2]).max() / np.abs(p1).max()
    check(same and d <= 1e-12, f"{track}: the plane x = 1 as one fault or as two meeting along y = 1: the same "
          f"{len(p1)} cells, the same pressure to {d:.1e} (1e-12)")
    return out


# Four faults through one point (a star of 8 arms, each ending on a held
# side): the junction's pressure sum g p / sum g over the arms (g = t / L)
# and each arm linear to it. Before 2026-12-04 a cell by it held more
# entries than its row's preallocation: PETSc error 63 on both tracks.
# The square [0, 4]^2 and four faults through its centre: a along y = 2,
# b along x = 2 (Lines 21-24), c and d through Points 9-12 (Lines 25-28),
# which each geometry places; the sides' lines and groups are each one's.
STAR_FRAME = """SetFactory("Built-in");
h = 0.25;
Point(1) = {0, 0, 0, h}; Point(2) = {4, 0, 0, h}; Point(3) = {4, 4, 0, h}; Point(4) = {0, 4, 0, h};
Point(5) = {0, 2, 0, h}; Point(6) = {4, 2, 0, h}; Point(7) = {2, 0, 0, h}; Point(8) = {2, 4, 0, h};
Point(13) = {2, 2, 0, h};
"""
STAR_FAULTS = """Line(21) = {5, 13}; Line(22) = {13, 6}; Line(23) = {7, 13}; Line(24) = {13, 8};
Line{21:28} In Surface{1};
Physical Curve("a") = {21, 22}; Physical Curve("b") = {23, 24}; Physical Curve("c") = {25, 26};
Physical Curve("d") = {27, 28}; Physical Surface("rock") = {1};
"""
STAR_GEO = STAR_FRAME + """\
Point(9) = {0, 1, 0, h}; Point(10) = {4, 3, 0, h}; Point(11) = {1, 0, 0, h}; Point(12) = {3, 4, 0, h};
Line(1) = {1, 11}; Line(2) = {11, 7}; Line(3) = {7, 2}; Line(4) = {2, 6}; Line(5) = {6, 10}; Line(6) = {10, 3};
Line(7) = {3, 12}; Line(8) = {12, 8}; Line(9) = {8, 4}; Line(10) = {4, 5}; Line(11) = {5, 9}; Line(12) = {9, 1};
Curve Loop(1) = {1:12}; Plane Surface(1) = {1};
Line(25) = {9, 13}; Line(26) = {13, 10}; Line(27) = {11, 13}; Line(28) = {13, 12};
Physical Curve("bottom") = {1, 2, 3}; Physical Curve("right") = {4, 5, 6}; Physical Curve("top") = {7, 8, 9};
Physical Curve("left") = {10, 11, 12};
""" + STAR_FAULTS
# per fault (alphabetical: fault.xdmf's ids) its aperture, normal and ends
STAR = {"a": (1.0e-4, "[0.0, 1.0]", ((0, 2, "left"), (4, 2, "right"))),
        "b": (2.0e-4, "[1.0, 0.0]", ((2, 0, "bottom"), (2, 4, "top"))),
        "c": (1.5e-4, "[-1.0, 2.0]", ((0, 1, "left"), (4, 3, "right"))),
        "d": (1.2e-4, "[2.0, -1.0]", ((1, 0, "bottom"), (3, 4, "top")))}


def check_star(track):
    faults = "".join(conduit(name, w, normal) for name, (w, normal, _) in STAR.items())
    out, _ = run_track(track, scene(STAR_GEO, 2, "".join(f"[boundary.{b}]\npressure = {p}\n"
                                                         for b, p in HELD.items()) + faults))
    J = np.array([2.0, 2.0])
    arms = [(f, np.array(end[:2], float), HELD[end[2]], w ** 3 / (12 * MU))
            for f, (w, _, ends) in enumerate(STAR.values()) for end in ends]
    g = [t / np.linalg.norm(e - J) for _, e, _, t in arms]
    p_j = sum(gi * p for gi, (_, _, p, _) in zip(g, arms)) / sum(g)
    x, ids, p = fault_pressure(out)
    exact = np.empty_like(p)
    for i, (f, c) in enumerate(zip(ids, x[:, :2])):
        _, e, p_e, _ = next(a for a in arms if a[0] == f and np.dot(c - J, a[1] - J) > 0)
        exact[i] = p_j + (p_e - p_j) * np.linalg.norm(c - J) / np.linalg.norm(e - J)
    error = np.abs(p - exact).max() / 3e6
    rate = summary(out)["intersections"]
    through = sum(max(gi * (p - p_j), 0.0) for gi, (_, _, p, _) in zip(g, arms))
    off = abs(rate["a & b & c & d"]["rate"] / through - 1) if list(rate) == ["a & b & c & d"] else np.inf
    check(error <= 1e-10 and off <= 1e-10 and sorted(set(ids.tolist())) == [0, 1, 2, 3],
          f"{track}: four faults through one point, the junction at {p_j / 1e6:.6f} MPa, every cell ({len(p)}) on "
          f"the arms' profiles to {error:.1e}, the rate through it the arms' to {off:.1e} (1e-10)")
    check_volumes(out, track, "2D, four faults through one point")
    return out


stars = {track: check_star(track) for track in ("C++", "prototype")}
(_, _, a), (_, _, b) = fault_pressure(stars["C++"]), fault_pressure(stars["prototype"])
check(np.abs(a - b).max() <= 1e-10 * np.abs(a).max(), "four faults through one point: the prototype's fault "
      f"pressure the C++'s to {np.abs(a - b).max() / np.abs(a).max():.1e} (1e-10)")


# The star under mechanics, its inclined faults ending inside the rock (a
# fault ending on a side with a prescribed displacement must cross it at a
# right angle), friction 0.6, a well into a: one pair opens, some slip, the
# rest stick; the Coulomb law at every pair, the volumes balanced, 2 ranks =
# 1 and the prototype = C++ (1e-8).
STAR_IN_ROCK_GEO = STAR_FRAME + """\
Point(9) = {1, 1, 0, h}; Point(10) = {3, 3, 0, h}; Point(11) = {1, 3, 0, h}; Point(12) = {3, 1, 0, h};
Line(1) = {1, 7}; Line(2) = {7, 2}; Line(3) = {2, 6}; Line(4) = {6, 3};
Line(5) = {3, 8}; Line(6) = {8, 4}; Line(7) = {4, 5}; Line(8) = {5, 1}; Curve Loop(1) = {1:8}; Plane Surface(1) = {1};
Line(25) = {9, 13}; Line(26) = {13, 10}; Line(27) = {12, 13}; Line(28) = {13, 11};
Physical Curve("bottom") = {1, 2}; Physical Curve("right") = {3, 4}; Physical Curve("top") = {5, 6};
Physical Curve("left") = {7, 8};
""" + STAR_FAULTS
STAR_IN_ROCK = """[mechanics]
E = 20.0e9
nu = 0.25
[coupling]
scheme = "monolithic"
alpha = 1.0
tolerance = 1e-10
[boundary.left]
displacement = { x = 0.0 }
pressure = 1e6
[boundary.bottom]
displacement = { y = 0.0 }
pressure = 1e6
[boundary.right]
traction = [-2.0e7, 0.0]
[boundary.top]
traction = [0.0, -3.0e7]
[well.inj]
fault = "a"
position = [1.0, 2.0]
rate = 5.0e-3
""" + "".join(conduit(f, w, n) + "friction = 0.6\n" for f, w, n in (
    ("a", 1.0e-4, "[0.0, 1.0]"), ("b", 2.0e-4, "[1.0, 0.0]"), ("c", 1.5e-4, "[-1.0, 1.0]"), ("d", 1.2e-4, "[1.0, 1.0]")))
STAR_FLOW = ["flow.permeability=1.0e-18", "flow.c_f=1.0e-9", "flow.M=1.0e10", "time.end=4.0"]


def check_star_in_rock():
    path = scene(STAR_IN_ROCK_GEO, 2, STAR_IN_ROCK)
    runs = {(track, ranks): run_track(track, path, *STAR_FLOW, ranks=ranks)[0]
            for track in ("C++", "prototype") for ranks in (1, 2)}
    one = runs[("C++", 1)]
    h = contact_history(one)
    state, excess = h["state"][-1], np.max(h["tau"] - 0.6 * h["sigma"]) / h["sigma"].max()
    check(summary(one)["converged"] and (state == 0).sum() > 0 and (state == 2).sum() > 0
          and (state == 1).sum() > 0 and excess <= 1e-8, f"C++: the star under mechanics, fed by a well: "
          f"{(state == 0).sum()} pairs open, {(state == 2).sum()} slipping, {(state == 1).sum()} stuck at the end; "
          f"|tau| - 0.6 sigma_n <= {excess:.1e} of the largest sigma_n (1e-8)")
    volumes = summary(one)["fault_volumes"]
    injected = volumes["a"]["injected"]
    worst = max(imbalance(v) for v in volumes.values()) / injected
    total = abs(sum(v["intersections"] for v in volumes.values())) / injected
    check(worst <= 1e-10 and total <= 1e-12 and min(volumes[f]["intersections"] for f in "bcd") > 0,
          f"C++, the star under mechanics: each fault balanced with the junction to {worst:.1e} of the injected "
          f"(1e-10), the junction's exchanges summing to {total:.1e} (1e-12); b, c and d fed through it")
    for (track, ranks), out in list(runs.items())[1:]:
        d = max_difference(one, out, ["displacement", "pressure"])
        same = [r["iteration"] for r in iterations(one)] == [r["iteration"] for r in iterations(out)]
        check(max(d.values()) <= 1e-8 and same, f"the star under mechanics: {track} on {ranks} rank(s) the C++ "
              f"1-rank run's fields {d} (1e-8) and coupling iterations")


check_star_in_rock()


def check_star_fed_faster():
    """The star fed at 1e-2 m^2/s: with the closed faults' transmissivities
    of its first aperture iteration the step's fluid has no equilibrium
    below dt = 1/128 s (the blocks that a and b cut lift off), so the step is
    halved (time.retry) until it passes and the steps grow back. The failed
    contact solves end at the divergence bound (contact/convergence.h):
    before it their clamped starts wandered to 1e22 N for 100 Newton steps
    each, 1,017 factorisations in the C++ run (now 292)."""
    path = scene(STAR_IN_ROCK_GEO, 2, STAR_IN_ROCK)
    for track in ("C++", "prototype"):
        out, p = run_track(track, path, *STAR_FLOW, "well.inj.rate=1.0e-2", expect=3)
        lines = p.stderr.strip().splitlines()
        check(len(lines) == 1 and "time.retry halves it, time.adaptive chooses it" in lines[0],
              f"{track}: the star fed at 1e-2 m^2/s on 1-s steps: exit 3, one line proposing time.retry and "
              f"time.adaptive ({lines[-1][-160:] if lines else ''!r})")
        # the failed solve's row: its Newton steps, no change (until
        # 2026-12-05 a step whose solve failed left no row)
        rows = iterations(out)
        check(len(rows) == 1 and rows[0]["step"] == "1" and int(rows[0]["newton_steps"]) > 0
              and rows[0]["dp_norm"] == rows[0]["du_norm"] == "", f"{track}: iterations.csv has the failed solve's "
              f"row with its Newton steps and no change ({rows})")
    runs = {track: run_track(track, path, *STAR_FLOW, "well.inj.rate=1.0e-2", "time.retry=10")[0]
            for track in ("C++", "prototype")}
    s = summary(runs["C++"])
    state = contact_history(runs["C++"])["state"][-1]
    volumes = s["fault_volumes"]
    worst = max(imbalance(v) for v in volumes.values()) / volumes["a"]["injected"]
    factorizations = s["solvers"]["monolithic"]["factorizations"]
    check(s["converged"] and s["retries"] >= 5 and (state == 0).sum() > 0 and worst <= 1e-10
          and factorizations <= 500, f"C++: the star fed at 1e-2 m^2/s converges after {s['retries']} halvings "
          f"of step 1, {(state == 0).sum()} pairs open at the end, balanced to {worst:.1e} of the injected "
          f"(1e-10), {factorizations} factorisations (at most 500)")
    d = max_difference(runs["C++"], runs["prototype"], ["displacement", "pressure"])
    check(max(d.values()) <= 1e-8 and summary(runs["prototype"])["retries"] == s["retries"],
          f"the star fed at 1e-2 m^2/s: the prototype the C++ run's fields {d} (1e-8) after as many halvings")


check_star_fed_faster()


# The faults' normal permeabilities: inf, and finite on b and c, which gives
# the intersections a resistance of their own.
JUNCTION_RESISTANCE = {"b": 2.0e-13, "c": 1.0e-13}
runs = {track: (check_kirchhoff(track, {}), check_crossing_planes(track), check_kirchhoff(track, JUNCTION_RESISTANCE))
        for track in ("C++", "prototype")}
for k, label in enumerate(("2D network", "3D crossing planes", "2D network with resistant intersections")):
    (_, _, a), (_, _, b) = fault_pressure(runs["C++"][k]), fault_pressure(runs["prototype"][k])
    d = np.abs(a - b).max() / np.abs(a).max()
    check(d <= 1e-10, f"{label}: the prototype's fault pressure the C++'s to {d:.1e} (1e-10)")


def check_shipped_network():
    out, _ = run_track("C++", shipped("network2d"))
    volumes = summary(out)["fault_volumes"]
    injected = volumes["f09"]["injected"]
    worst = max(imbalance(v) for v in volumes.values()) / injected
    total = abs(sum(v["intersections"] for v in volumes.values())) / injected
    _, ids, p = fault_pressure(out)
    names = sorted(f"f{i:02d}" for i in range(1, 23))  # fault.xdmf's fault ids: alphabetical over every fault
    rise = {name: (p[ids == k].max() - 1.0e7) / 1e6 for k, name in enumerate(names) if name in volumes}
    reached = ["f09", "f02", "f16", "f05", "f18"]
    others = max(rise[name] for name in rise if name not in reached)
    check(len(volumes) == 17 and abs(injected - 2.0e-5 * 864000.0) <= 1e-12 * injected and worst <= 1e-8
          and total <= 1e-12 and min(rise[name] for name in reached) > 2.0 and max(rise, key=rise.get) == "f09"
          and others < 0.5, f"network2d: {len(volumes)} conduits, {injected:g} m^2 injected into f09, each balanced "
          f"to {worst:.1e} (1e-8), the intersections summing to {total:.1e}; the pressure rises "
          f"{', '.join(f'{n} {rise[n]:.2f}' for n in reached)} MPa along the fractures f09 meets, at most "
          f"{others:.2f} MPa in the others")
    check_shipped_contact(out)


def check_shipped_contact(out):
    """network2d's contact: the Coulomb law at every pair and output time,
    slip from the in-situ stress on, growing with the injection."""
    s = summary(out)
    h = contact_history(out)
    sigma, tau, opening, slip, state = h["sigma"], h["tau"], h["opening"], h["slip"], h["state"]
    scale = sigma.max()
    excess = np.max(tau - 0.6 * sigma) / scale
    check(s["converged"] and s["status"] == "completed" and opening.min() >= -1e-12 and sigma.min() >= 0.0
          and excess <= 1e-8, f"network2d: converged; the faces apart or touching (opening >= {opening.min():.1e} m), "
          f"the traction compressive and within the Coulomb disc (|tau| - 0.6 sigma_n <= {excess:.1e} of the largest "
          "sigma_n)")
    slipping = (state == 2).sum(axis=1)
    check(slipping[0] > 0 and slipping[-1] > 0 and slip[-1].max() > slip[0].max(),
          f"network2d: {slipping[0]} pairs slip under the in-situ stress, {slipping[-1]} after ten days of "
          f"injection; the largest slip {slip[0].max():.4f} -> {slip[-1].max():.4f} m")


check_shipped_network()


def check_shipped_network3d():
    """network3d (its first step): f2's edges cross f1 (a tip line across
    a fault), which both tracks split; the injection into f1 reaches f2
    through the X and makes more of f1 slip; the prototype's run is the
    C++ one."""
    runs = {}
    for track in TRACKS:
        p = subprocess.run(TRACKS[track] + ["check", shipped("network3d")], capture_output=True, text=True,
                           cwd=ROOT, env=MPI_ENV)
        check(p.returncode == 0, f"{track}: network3d passes check, f2's edges across f1 ({p.stderr.strip()!r})")
        out = runs[track] = run_track(track, shipped("network3d"), "time.end=1800.0")[0]
        s, volumes = summary(out), summary(out)["fault_volumes"]
        worst = max(imbalance(v) for v in volumes.values()) / volumes["f1"]["injected"]
        check(sorted(volumes) == ["f1", "f2"] and worst <= 1e-8 and volumes["f2"]["intersections"] > 0
              and s["converged"], f"{track}, network3d: converged; f1 and f2 balanced to {worst:.1e} (1e-8), "
              f"{volumes['f2']['intersections']:.3g} m^3 into f2 through the X")
        h = contact_history(out)
        sigma, tau, opening = h["sigma"], h["tau"], h["opening"]
        slipping = (h["state"] == 2).sum(axis=1)
        excess = np.max(tau - 0.6 * sigma) / sigma.max()
        check(opening.min() >= -1e-12 and sigma.min() >= 0.0 and excess <= 1e-8 and 0 < slipping[0] < slipping[-1],
              f"{track}, network3d: faces apart or touching (opening >= {opening.min():.1e} m), tractions "
              f"compressive and in the Coulomb disc (excess {excess:.1e}); {slipping[0]} pairs slip under the "
              f"in-situ stress, {slipping[-1]} after half an hour of injection")
    d = max_difference(runs["C++"], runs["prototype"], ("displacement", "pressure", "contact_pressure"))
    steps = {track: [(r["step"], r["iteration"]) for r in iterations(out)] for track, out in runs.items()}
    check(max(d.values()) <= 1e-10 and steps["C++"] == steps["prototype"],
          "network3d: the prototype's fields are the C++ ones to 1e-10 ("
          + ", ".join(f"{k} {v:.1e}" for k, v in d.items()) + "), the same coupling iterations")


check_shipped_network3d()
