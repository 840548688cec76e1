"""Load, unload and reload with friction 0.6 (issue 50, verification 5), both
tracks: the closed-form hysteresis of Cattaneo-Mindlin and of
Mindlin-Deresiewicz (docs/verification.md, "Cattaneo-Mindlin: partial slip
under a cycle"), plane strain. A square cut by the fault y = 0 with the
Hertzian gap x^2/(2R), pressed, then moved sideways 0 -> S -> -S -> S in 4 +
8 + 8 steps: at every step the stuck pairs are one centred interval of
measure 2c (2c') within 3 %, the slipping ones slip along the step, a within
3 % of Hertz's, every step converges; the prototype equals C++ (1e-10, the
same states). 3D, no closed form: a box cut by a horizontal fault under the
same cycle: every step converges, Coulomb holds (1e-9), the reloading
mirrors the unloading (3 %). Numbers: docs/verification.md."""
import math
import os

import h5py
import numpy as np
from support import check, fault_fields, gmsh_scene, max_difference, run_track, summary, written

E, NU, MU, R = 1.0e9, 0.25, 0.6, 1.0
PUSH, S = 4.5e-3, 3.0e-3         # the top's displacement down (step 1), the amplitude of its sideways one
SPACING = 5.0e-4                 # the pairs' spacing near the contact
LOAD, CYCLE = 4, 8               # steps of the loading, of the unloading, of the reloading
STEPS = 1 + LOAD + 2 * CYCLE
TOLERANCE = 0.03
# The square cut by the fault y = 0 (three lines: the middle one, |x| < 0.07,
# meshed at SPACING, the mesh growing to 0.1 m away from it).
GEO = f"""SetFactory("Built-in");
L = 1; b = 0.07; h = {SPACING!r};
Point(1) = {{-L, -L, 0}}; Point(2) = {{L, -L, 0}}; Point(3) = {{L, 0, 0}}; Point(4) = {{L, L, 0}};
Point(5) = {{-L, L, 0}}; Point(6) = {{-L, 0, 0}}; Point(7) = {{-b, 0, 0}}; Point(8) = {{b, 0, 0}};
Line(1) = {{1, 2}}; Line(2) = {{2, 3}}; Line(3) = {{3, 4}}; Line(4) = {{4, 5}}; Line(5) = {{5, 6}}; Line(6) = {{6, 1}};
Line(7) = {{6, 7}}; Line(8) = {{7, 8}}; Line(9) = {{8, 3}};
Curve Loop(1) = {{1, 2, -9, -8, -7, 6}}; Plane Surface(1) = {{1}};
Curve Loop(2) = {{7, 8, 9, 3, 4, 5}}; Plane Surface(2) = {{2}};
Physical Curve("bottom") = {{1}}; Physical Curve("top") = {{4}};
Physical Curve("left") = {{5, 6}}; Physical Curve("right") = {{2, 3}};
Physical Curve("fault") = {{7, 8, 9}};
Physical Surface("lower") = {{1}}; Physical Surface("upper") = {{2}};
Field[1] = Distance; Field[1].CurvesList = {{8}}; Field[1].NumPointsPerCurve = 400;
Field[2] = Threshold; Field[2].InField = 1; Field[2].SizeMin = h; Field[2].SizeMax = 0.1;
Field[2].DistMin = 0.01; Field[2].DistMax = 0.8;
Background Field = 2;
Mesh.CharacteristicLengthExtendFromBoundary = 0;
Mesh.CharacteristicLengthFromPoints = 0;
"""
TURNS = (1 + LOAD, 1 + LOAD + CYCLE)   # the steps that end the loading and the unloading
SIDEWAYS = (f"{S!r} * (t <= 1 ? 0 : (t <= {TURNS[0]} ? (t - 1) / {LOAD} : (t <= {TURNS[1]} ? "
            f"1 - 2 * (t - {TURNS[0]}) / {CYCLE} : -1 + 2 * (t - {TURNS[1]}) / {CYCLE})))")
SCENE = f"""[scene]
name = "friction_cycles"
[mesh]
type = "gmsh"
file = "cycles.geo"
dimension = 2
[mechanics]
E = {E!r}
nu = {NU!r}
[time]
end = {float(STEPS)!r}
dt = 1.0
[boundary.bottom]
clamp = true
[boundary.top]
displacement = {{ x = "{SIDEWAYS}", y = {-PUSH!r} }}
[fault.fault]
friction = {MU!r}
gap = "x^2/(2*{R!r})"
normal = [0.0, 1.0]
"""


def cycle_scene():
    path = written(SCENE)
    with open(os.path.join(os.path.dirname(path), "cycles.geo"), "w") as f:
        f.write(GEO)
    return path


def lumped_lengths(out):
    """Each pair's lumped length: half of each fault segment to each of its
    two nodes (fault.h5's mesh, the + face)."""
    with h5py.File(os.path.join(out, "fault.h5")) as f:
        x, cells = f["Mesh/geometry"][:], f["Mesh/topology"][:]
    half = 0.5 * np.linalg.norm(x[cells[:, 1]] - x[cells[:, 0]], axis=1)
    lumped = np.zeros(len(x))
    np.add.at(lumped, cells[:, 0], half)
    np.add.at(lumped, cells[:, 1], half)
    return lumped


def measures(out):
    """Per output time: P, Q, a, the stuck and slipping measures, and the
    pairs' x, states and slip increments along x."""
    x, _, series = fault_fields(out, ("state", "traction", "tangential_traction", "slip_increment"))
    lumped = lumped_lengths(out)
    result = []
    for f in series:
        state = f["state"][:, 0]
        result.append({"x": x[:, 0], "state": state, "increment": f["slip_increment"][:, 0],
                       "P": np.sum(f["traction"][:, 0] * lumped), "Q": np.sum(f["tangential_traction"][:, 0] * lumped),
                       "a": 0.5 * np.sum(lumped[state > 0]), "stuck": np.sum(lumped[state == 1]),
                       "slipping": np.sum(lumped[state == 2])})
    return result


def stick_half_width(m, reversal):
    """Cattaneo-Mindlin's c (reversal None: loading from Q = 0), or Mindlin
    and Deresiewicz's c' after a reversal at the tangential load `reversal`."""
    if reversal is None:
        return m["a"] * math.sqrt(max(1 - abs(m["Q"]) / (MU * m["P"]), 0.0))
    return m["a"] * math.sqrt(max(1 - abs(reversal - m["Q"]) / (2 * MU * m["P"]), 0.0))


def check_step(track, k, m, reversal, direction):
    """Step k's stuck and slipping measures against the closed form, its
    stick zone one central interval, its pairs slipping along `direction`."""
    c, a = stick_half_width(m, reversal), m["a"]
    error = (m["stuck"] - 2 * c) / max(2 * c, 1e-300)
    slip_error = (m["slipping"] - 2 * (a - c)) / (2 * a)
    check(abs(error) <= TOLERANCE and abs(slip_error) <= TOLERANCE,
          f"{track}: step {k}, Q/(mu P) = {m['Q'] / (MU * m['P']):+.4f}: c/a {m['stuck'] / (2 * a):.4f}, closed form "
          f"{c / a:.4f} ({100 * error:+.2f} %, 3 %); slipping {m['slipping'] * 1e3:.2f} mm, closed form "
          f"{2e3 * (a - c):.2f} mm ({100 * slip_error:+.2f} % of 2a, 3 %)")
    stuck, slipping = m["state"] == 1, m["state"] == 2
    ends = (m["x"][stuck].min(), m["x"][stuck].max()) if stuck.any() else (np.inf, -np.inf)
    inside = (m["state"] > 0) & (m["x"] >= ends[0]) & (m["x"] <= ends[1])
    along = np.all(np.sign(m["increment"][slipping]) == direction)
    centred = abs(ends[0] + ends[1]) / 2 <= SPACING
    check(stuck.any() and np.all(stuck[inside]) and centred and along, f"{track}: step {k}: the stuck pairs one "
          f"interval [{ends[0]:.4f}, {ends[1]:.4f}] m centred to a pair spacing, the {np.count_nonzero(slipping)} "
          f"slipping pairs slip {'forward' if direction > 0 else 'back'}")


def check_hysteresis(track, out):
    """Every step of the cycle against Cattaneo-Mindlin and
    Mindlin-Deresiewicz; a against Hertz's."""
    steps = measures(out)
    a, P = steps[1]["a"], steps[1]["P"]
    hertz = math.sqrt(8 * P * R * (1 - NU ** 2) / (math.pi * E))
    check(abs(a / hertz - 1) <= TOLERANCE and a / SPACING >= 40, f"{track}: a = {a:.5f} m ({a / SPACING:.1f} pair "
          f"spacings), Hertz {hertz:.5f} m ({100 * (a / hertz - 1):+.2f} %, 3 %)")
    peak = steps[TURNS[0]]["Q"] / (MU * steps[TURNS[0]]["P"])
    check(0.5 <= peak < 0.9, f"{track}: partial slip: Q*/(mu P) = {peak:.4f}")
    for k in range(1, STEPS + 1):
        reversal = None if k <= TURNS[0] else steps[TURNS[0] if k <= TURNS[1] else TURNS[1]]["Q"]
        direction = -1 if TURNS[0] < k <= TURNS[1] else 1
        check_step(track, k, steps[k], reversal, direction)
    return steps


def check_converged(track, out, last):
    """Every step converged, and summary.json's measures are fault.xdmf's."""
    s = summary(out)
    moments = s["seismic_moment"]["fault"]["times"]
    check(s["converged"] and s["status"] == "completed" and s["steps"] == STEPS and s["retries"] == 0
          and len(moments) == STEPS, f"{track}: all {STEPS} steps converged, none retried "
          f"({s['newton_iterations']} Newton steps, {s['wall_time_s']:.1f} s)")
    fault = s["contact"]["faults"]["fault"]
    worst = max(abs(fault["stuck"] - last["stuck"]), abs(fault["slipping"] - last["slipping"]),
                abs(fault["closed"] - 2 * last["a"]))
    check(worst <= 1e-12 * fault["closed"], f"{track}: summary.json's stuck, slipping and closed measures are "
          f"fault.xdmf's ({worst:.1e} m)")


runs = {}
for track in ("C++", "prototype"):
    out, _ = run_track(track, cycle_scene())
    steps = check_hysteresis(track, out)
    check_converged(track, out, steps[-1])
    runs[track] = out
d = max_difference(runs["C++"], runs["prototype"], ["displacement"])
states = [np.array_equal(a["state"], b["state"]) for a, b in zip(fault_fields(runs["C++"], ("state",))[2],
                                                                    fault_fields(runs["prototype"], ("state",))[2])]
check(d["displacement"] <= 1e-10 and all(states), f"the prototype equals the C++ solver: displacement "
      f"{d['displacement']:.1e} (1e-10), the same states at all {len(states)} output times")


# 3D: a box [0, 1]^2 x [0, 1] cut by the fault z = 0.5, bottom clamped, the
# top pressed down by 1 mm (step 1) and moved along x: 0 -> 3 mm in 4 steps,
# back to -3 mm in 8, to 3 mm in 8 (t = 1 ... 21).
BOX_GEO = """SetFactory("OpenCASCADE");
Box(1) = {0, 0, 0, 1, 1, 0.5};
Box(2) = {0, 0, 0.5, 1, 1, 0.5};
BooleanFragments{ Volume{1}; Delete; }{ Volume{2}; Delete; }
e = 1e-6;
Physical Surface("fault") = {Surface In BoundingBox{-e, -e, 0.5 - e, 1 + e, 1 + e, 0.5 + e}};
Physical Surface("bottom") = {Surface In BoundingBox{-e, -e, -e, 1 + e, 1 + e, e}};
Physical Surface("top") = {Surface In BoundingBox{-e, -e, 1 - e, 1 + e, 1 + e, 1 + e}};
Physical Volume("rock") = {Volume{:}};
Mesh.CharacteristicLengthMax = 0.1;
"""
SHIFT = "(t <= 1 ? 0 : (t <= 5 ? 3e-3*(t-1)/4 : (t <= 13 ? 3e-3 - 6e-3*(t-5)/8 : -3e-3 + 6e-3*(t-13)/8)))"
BOX = f"""[boundary.bottom]
displacement = {{ x = 0.0, y = 0.0, z = 0.0 }}
[boundary.top]
displacement = {{ x = "{SHIFT}", y = 0.0, z = -1.0e-3 }}
[fault.fault]
normal = [0.0, 0.0, 1.0]
friction = {MU}
"""


def check_box_cycle(track, out):
    """The 3D cycle's convergence, Coulomb law, stick after each turn and
    mirrored slip."""
    s = summary(out)
    check(s["converged"] and s["status"] == "completed" and s["steps"] == 21 and s["retries"] == 0,
          f"3D ({track}): all 21 steps of the cycle converged, none retried ({s['newton_iterations']} Newton steps)")
    _, times, series = fault_fields(out, ("slip", "traction", "tangential_traction", "state"))
    at = {round(t): f for t, f in zip(times, series) if t >= 1}  # from the step that presses on
    largest = max(f["traction"].max() for f in at.values())
    law = 0.0
    for f in at.values():
        tn, tt, state = f["traction"].ravel(), np.linalg.norm(f["tangential_traction"], axis=1), f["state"].ravel()
        slipping, stuck = state == 2, state == 1
        law = max(law, np.abs(tt - MU * tn)[slipping].max(initial=0.0), (tt - MU * tn)[stuck].max(initial=0.0))
    check(law <= 1e-9 * largest and all((f["state"] > 0).all() for f in at.values()),
          f"3D ({track}): no pair open, the Coulomb law at every pair and step to {law / largest:.1e} of the "
          "largest traction (1e-9)")
    mean = {t: f["slip"][:, 0].mean() for t, f in at.items()}
    turned = all((at[t]["state"] == 1).all() for t in (6, 7, 8, 14, 15, 16))
    gross = all((at[t]["state"] == 2).all() for t in (5, 13, 21))
    mirrored = max(abs(mean[13 + k] + mean[5 + k]) for k in range(9)) / abs(mean[5])
    check(turned and gross and mirrored <= TOLERANCE,
          f"3D ({track}): every pair sticks for three steps after each turn and slips at each amplitude; the "
          f"reloading's mean slip the unloading's mirrored to {mirrored:.2%} of {mean[5]:.3e} m (3 %)")


boxes = {track: run_track(track, gmsh_scene(BOX_GEO, BOX, dimension=3, end=21.0))[0] for track in ("C++", "prototype")}
for track, out in boxes.items():
    check_box_cycle(track, out)
d = max_difference(boxes["C++"], boxes["prototype"], ["displacement"])["displacement"]
check(d <= 1e-10, f"3D: the prototype equals the C++ solver on the cycle: displacement {d:.1e} (1e-10)")
