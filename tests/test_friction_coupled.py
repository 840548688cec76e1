"""Friction through the coupled solve (issue 38), both tracks: a crack with mu
= 0.7 under 10 MPa, its faces loaded by the pore pressure beside them, the
fluid driven in from the left: some pairs slip and some stick; split =
monolithic (fields to 1e-9, the same stick/slip states), also with
Anderson; iterations.csv's Newton steps add up to the summary's; the
split's largest contraction ratio printed against Theorem 1's gamma
(frictionless theory); prototype = C++ (1e-10); multirate q = 2 and its
two-pass variant reach the same fixed point (1e-10, the same states);
fault_reactivation's first 14 days: split = monolithic (1e-7, the same
states). Numbers: docs/verification.md, "What each test verifies"."""
import os

import numpy as np
from support import INCLINED_CRACK_GEO as GEO, check, fault_fields, iterations, max_difference, run_track, summary
from support import written
from support import scene as scene_file

SCENE = """[mesh]
type = "gmsh"
file = "crack.geo"
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
scheme = "{scheme}"
[time]
end = 1.0
dt = 0.1
[boundary.left]
pressure = "4.0e6 * t"
displacement = {{ x = 0.0 }}
[boundary.right]
pressure = 0.0
[boundary.bottom]
displacement = {{ y = 0.0 }}
[boundary.top]
traction = [0.0, -1.0e7]
[fault.crack]
friction = 0.7
pore_pressure_load = true
normal = [-0.5, 0.8660254037844386]
"""
FIELDS = ["displacement", "pressure", "flux"]


def scene(scheme):
    path = written(SCENE.format(scheme=scheme))
    with open(os.path.join(os.path.dirname(path), "crack.geo"), "w") as f:
        f.write(GEO)
    return path


runs = {}
for track in ("C++", "prototype"):
    split, _ = run_track(track, scene("fixed-stress"))
    monolithic, _ = run_track(track, scene("monolithic"))
    _, times, states = fault_fields(split)
    slipping = [int(np.count_nonzero(f["state"][:, 0] == 2)) for f in states]
    stuck = [int(np.count_nonzero(f["state"][:, 0] == 1)) for f in states]
    check(max(slipping) > 0 and max(stuck) > 2, f"{track}: pairs slipping at each output time {slipping}, stuck "
          f"{stuck}")
    same = all(np.array_equal(a["state"], b["state"]) for a, b in zip(states, fault_fields(monolithic)[2]))
    check(same, f"{track}: the split and the monolithic solve have the same stick/slip states at all "
          f"{len(times)} output times")
    coupled = max_difference(split, monolithic, FIELDS)
    check(max(coupled.values()) <= 1e-9, f"{track}: the split equals the monolithic solve: {coupled} (1e-9)")
    anderson, _ = run_track(track, scene("fixed-stress"), "coupling.acceleration=anderson")
    accelerated = max_difference(anderson, monolithic, FIELDS)
    check(max(accelerated.values()) <= 1e-9, f"{track}: the split with Anderson acceleration equals the monolithic "
          f"solve: {accelerated} (1e-9; {summary(anderson)['coupling_iterations']} coupling iterations against "
          f"{summary(split)['coupling_iterations']})")
    report = summary(split)
    steps = [int(r["newton_steps"]) for r in iterations(split)]
    # A coupling iteration whose mechanics starts solved (its residual below
    # the tolerance: friction's F is not linear, no forced step) takes none.
    check(sum(steps) == report["solvers"]["mechanics"]["newton_iterations"] and max(steps) >= 1,
          f"{track}: iterations.csv's newton_steps, median {np.median(steps):g} per coupling iteration "
          f"({steps.count(0)} of {len(steps)} with none), add up to the "
          f"{report['solvers']['mechanics']['newton_iterations']} Newton steps of summary.json")
    print(f"{track}: largest contraction ratio {report['max_contraction_ratio']:.4f}, mean "
          f"{report['mean_contraction_ratio']:.4f}, gamma {report['gamma']:.4f} (Theorem 1: frictionless, rigid "
          f"foundation)")
    runs[track] = split
tracks = max_difference(runs["C++"], runs["prototype"], FIELDS)
check(max(tracks.values()) <= 1e-10, f"the prototype equals the C++ solver: {tracks} (1e-10)")

MULTIRATE = ["coupling.q=2", "coupling.tolerance=1e-12"]
multirate = {}
for track in ("C++", "prototype"):
    printed, _ = run_track(track, scene("multirate"), *MULTIRATE)
    two_pass, _ = run_track(track, scene("multirate-two-pass"), *MULTIRATE)
    reports = [summary(printed), summary(two_pass)]
    check(all(r["converged"] for r in reports), f"{track}: multirate and two-pass converge with friction in "
          f"{[r['coupling_iterations'] for r in reports]} coupling iterations, largest contraction ratios "
          f"{[round(r['max_contraction_ratio'], 4) for r in reports]}")
    same = all(np.array_equal(a["state"], b["state"])
               for a, b in zip(fault_fields(printed)[2], fault_fields(two_pass)[2]))
    fixed_point = max_difference(printed, two_pass, FIELDS)
    check(same and max(fixed_point.values()) <= 1e-10, f"{track}: multirate and two-pass have the same fixed point "
          f"with friction: the same states, fields {fixed_point} (1e-10)")
    multirate[track] = printed
tracks = max_difference(multirate["C++"], multirate["prototype"], FIELDS)
check(max(tracks.values()) <= 1e-10, f"multirate with friction: the prototype equals the C++ solver: {tracks} (1e-10)")

REACTIVATION = scene_file("fault_reactivation")
DAYS = ["time.end=1209600.0"]
split, _ = run_track("C++", REACTIVATION, *DAYS)
monolithic, _ = run_track("C++", REACTIVATION, *DAYS, "coupling.scheme=monolithic")
_, times, states = fault_fields(split)
slipping = [int(np.count_nonzero(f["state"][:, 0] == 2)) for f in states]
check(slipping[0] == 0 and slipping[-1] > 10, f"fault_reactivation: pairs slipping each day {slipping}")
same = all(np.array_equal(a["state"], b["state"]) for a, b in zip(states, fault_fields(monolithic)[2]))
coupled = max_difference(split, monolithic, FIELDS)
check(same and max(coupled.values()) <= 1e-7, f"fault_reactivation: split = monolithic, the same states at all "
      f"{len(times)} output times, fields {coupled} (1e-7)")
