"""Flow inside a conduit fault (issue 39; docs/theory.md, "Flow in a fault"),
both tracks: a fault across a 10 m x 2 m rock, rigid walls, w = 1e-4 m.
Against closed forms to 1e-10: the cubic law's linear pressure and flux in
an impermeable rock (and k_f w with the fault's own permeability, issue
52); a well at the middle: the pressure tent, half the rate out of each
end; a finite normal permeability across the rock's flow: the series
resistance. Transient storage w c_f: the erfc profile within 1 % of dp; a
fault far less transmissive than the rock is transparent (1e-6); 2 ranks =
1 (also for a fault one rank holds), a restart ends equal, prototype = C++ (and fault.xdmf's XML); in 3D p_f
is linear to the mesh's error (2 % asserted: the two-point flux on
triangles) and a vertical well raises p_f most where it crosses. Numbers:
docs/verification.md."""
import math
import os

import h5py
import numpy as np
from support import (BOX_GEO, CHANNEL_GEO, Fields, check, fault_centroids, fault_fields, killed_and_restarted,
                     max_difference, run_track, summary, written)

SCENE = """[mesh]
type = "gmsh"
file = "channel.geo"
dimension = 2
[flow]
mu_f = 1.0e-3
permeability = {permeability}
c_f = {c_f}
initial_pressure = 1.0e6
[time]
end = {end}
dt = {dt}
[boundary.left]
pressure = {left}
[boundary.right]
pressure = 1.0e6
[fault.crack]
{fault}
"""
CONDUIT = 'flow = "conduit"\nresidual_aperture = {w}'
W, MU, C_F, L, DP = 1.0e-4, 1.0e-3, 1.0e-9, 10.0, 1.0e6
K_F = 1.0e-6  # a fault's own permeability (m^2), 1200 times the cubic law's w^2 / 12


# The channel scene's values (scene's `changes` override them): the rock's
# permeability, the fluid's compressibility, the time, the cell size and the
# pressure held on the left.
CHANNEL = {"permeability": 1.0e-25, "c_f": 0.0, "end": 1.0, "dt": 1.0, "size": 0.25, "left": 2.0e6}


def scene(fault, well="", **changes):
    values = dict(CHANNEL, **changes)
    path = written(SCENE.format(fault=fault, **values) + well)
    with open(os.path.join(os.path.dirname(path), "channel.geo"), "w") as f:
        f.write(CHANNEL_GEO.replace("h = 0.25", f"h = {values['size']}"))
    return path


def cells(out, time=-1):
    """The fault cells' x, pressure, flux and exchange at an output time."""
    _, _, series = fault_fields(out, ("pressure", "flux", "exchange"))
    f = series[time]
    return fault_centroids(out)[:, 0], f["pressure"][:, 0], f["flux"], f["exchange"][:, 0]


CROSS_GEO = CHANNEL_GEO.replace("Point(6) = {0, 0, 0, h};", "Point(6) = {0, 0, 0, h}; Point(7) = {5, -1, 0, h}; "
                        "Point(8) = {5, 1, 0, h};").replace("Line(7) = {6, 3};", "Line(7) = {7, 8};").replace(
    "Line(1) = {1, 2};", "Line(1) = {1, 7}; Line(9) = {7, 2};").replace(
    "Line(4) = {4, 5};", "Line(4) = {4, 8}; Line(10) = {8, 5};").replace(
    "Curve Loop(1) = {1, 2, 3, 4, 5, 6};", "Curve Loop(1) = {1, 9, 2, 3, 4, 10, 5, 6};").replace(
    'Physical Curve("bottom") = {1};', 'Physical Curve("bottom") = {1, 9};').replace(
    'Physical Curve("top") = {4};', 'Physical Curve("top") = {4, 10};')
K_N = 1.0e-17


def check_normal_permeability(track):
    """The fault across the flow, with k_n = K_N: the flux in every cell and
    p_f against the series resistances."""
    path = scene(CONDUIT.format(w=W) + f"\nnormal_permeability = {K_N}\nnormal = [1.0, 0.0]", permeability=1.0e-12)
    with open(os.path.join(os.path.dirname(path), "channel.geo"), "w") as f:
        f.write(CROSS_GEO)
    out, _ = run_track(track, path)
    fields = Fields(out)
    flux = fields.at("flux", fields.times("flux")[-1])
    exact = DP / (MU * L / 1.0e-12 + MU * W / K_N)
    error = max(np.max(np.abs(flux[:, 0] - exact)), np.max(np.abs(flux[:, 1]))) / exact
    p_f = cells(out)[1]
    middle = np.max(np.abs(p_f - 1.5e6)) / DP
    check(error <= 1e-10 and middle <= 1e-10, f"{track}: across a normal permeability of {K_N:g} m^2 the flux is "
          f"{np.mean(flux[:, 0]):.6e} m/s in every cell, the series resistances' {exact:.6e}: {error:.1e}; p_f "
          f"1.5 MPa to {middle:.1e} (1e-10)")


# A fault inside the rock near the outlet, which one of 2 ranks holds
# whole, with a normal permeability: the other rank takes part in making
# A + D though it owns no row of D (it waited for the first for ever in the
# conduit system's set-up until 2026-12-04).
TIP_GEO = CHANNEL_GEO.replace("Point(6) = {0, 0, 0, h};", "Point(6) = {0, 0, 0, h}; Point(7) = {8, 0, 0, h}; "
                              "Point(8) = {9.5, 0, 0, h};").replace("Line(7) = {6, 3};", "Line(7) = {7, 8};")


def check_fault_on_one_rank(track):
    """2 ranks give the fields and p_f of 1 rank on TIP_GEO."""
    path = scene(CONDUIT.format(w=W) + f"\nnormal_permeability = {K_N}", permeability=1.0e-15, c_f=C_F, end=2.0)
    with open(os.path.join(os.path.dirname(path), "channel.geo"), "w") as f:
        f.write(TIP_GEO)
    one, _ = run_track(track, path)
    two, _ = run_track(track, path, ranks=2)
    fields = max_difference(one, two, ["pressure", "flux"], sort=True)
    a, b = cells(one), cells(two)
    fault = np.max(np.abs(np.sort(a[1]) - np.sort(b[1]))) / DP
    check(max(fields.values()) <= 1e-10 and fault <= 1e-10 and len(a[1]) > 0,
          f"{track}: a fault that one of 2 ranks holds whole: the fields of 1 rank {fields}, p_f of its "
          f"{len(a[1])} cells to {fault:.1e} (1e-10)")


def check_linear_flow(out, track, law="the cubic law", transmissivity=W ** 3 / 12):
    """The fault's pressure linear and its flux transmissivity dp / (mu_f L)
    in every cell, none into the rock."""
    x, p, q, exchange = cells(out)
    linear = np.max(np.abs(p - (2.0e6 - DP * x / L))) / DP
    check(linear <= 1e-10, f"{track}, {law}: the fault's pressure is linear to {linear:.1e} (1e-10)")
    exact = transmissivity * DP / (MU * L)
    error = max(np.max(np.abs(q[:, 0] - exact)), np.max(np.abs(q[:, 1:]))) / exact
    check(error <= 1e-10, f"{track}: flux {q[0, 0]:.6e} m^2/s in every cell, {law}'s {exact:.6e}: "
          f"{error:.1e} (1e-10)")
    leak = np.max(np.abs(exchange)) * L / exact
    check(leak <= 1e-10, f"{track}, {law}: the rock takes {leak:.1e} of the flux (1e-10)")


WELL = """[well.inj]
fault = "crack"
position = [5.0, 0.0]
rate = 1.0e-6
"""
Q = 1.0e-6


def check_well(out, track):
    x, p, q, _ = cells(out)
    t = W ** 3 / (12 * MU)
    tent = 1.0e6 + (Q / 2) * (L / 2 - np.abs(x - L / 2)) / t
    error = np.max(np.abs(p - tent)) / np.max(tent - 1.0e6)
    ends = [np.argmin(x), np.argmax(x)]
    outflow = max(abs(abs(q[k, 0]) - Q / 2) for k in ends) / Q
    check(error <= 1e-10 and outflow <= 1e-10, f"{track}: a well into the fault: p_f the tent to {error:.1e}, Q/2 "
          f"out of each end to {outflow:.1e} (1e-10)")
    v = summary(out)["fault_volumes"]["crack"]
    errors = [abs(v["injected"] - Q), abs(v["outflow"] - Q), abs(v["stored"]), abs(v["exchanged"])]
    check(max(errors) <= 1e-10 * Q, f"{track}: summary.json: the well injected {v['injected']:.6e} m^2 in 1 s, "
          f"as much flowed out of the ends ({v['outflow']:.6e}), nothing stored, to {max(errors) / Q:.1e} (1e-10)")


def check_filling(out, track):
    """The transient fault fills through its inlet: summary.json's volumes."""
    _, p, _, _ = cells(out)
    with h5py.File(os.path.join(out, "fault.h5")) as f:
        nodes, segments = f["Mesh/geometry"][:], f["Mesh/topology"][:]
    lengths = np.linalg.norm(nodes[segments[:, 1]] - nodes[segments[:, 0]], axis=1)
    stored = C_F * W * np.sum(lengths * (p - 1.0e6))
    v = summary(out)["fault_volumes"]["crack"]
    errors = [abs(v["stored"] - stored), abs(v["stored"] + v["outflow"] - v["exchanged"]), abs(v["injected"])]
    check(max(errors) <= 1e-10 * stored, f"{track}: summary.json: the fault stored {v['stored']:.6e} m^2 = c_f w "
          f"sum |k| (p_f - p0), as much flowed in at the inlet (outflow {v['outflow']:.6e}), to "
          f"{max(errors) / stored:.1e} (1e-10)")


def check_erfc(out, track):
    D = W ** 2 / (12 * MU * C_F)
    _, times, _ = fault_fields(out, ())
    worst = []
    for t in (2.5e-4, 5.0e-4, 1.0e-3):
        x, p, _, _ = cells(out, times.index(min(times, key=lambda s: abs(s - t))))
        exact = 1.0e6 + DP * np.array([math.erfc(v / (2 * math.sqrt(D * t))) for v in x])
        worst.append(np.max(np.abs(p - exact)) / DP)
    check(max(worst) <= 0.01, f"{track}: p_f follows the erfc solution (D = {D:.4g} m^2/s) to "
          f"{', '.join(f'{w:.2%}' for w in worst)} of dp at 0.25, 0.5, 1 ms (1 %)")


WELL3D = WELL.replace("position = [5.0, 0.0]", "position = [2.0, 0.5]\nbottom = -0.5\ntop = 0.5")


def box_scene(well=""):
    path = written(SCENE.format(permeability=1.0e-25, c_f=0.0, end=1.0, dt=1.0, fault=CONDUIT.format(w=W),
                                left=2.0e6).replace('"channel.geo"', '"box.geo"').replace("dimension = 2",
                                                                                          "dimension = 3") + well)
    with open(os.path.join(os.path.dirname(path), "box.geo"), "w") as f:
        f.write(BOX_GEO)
    return path


def check_3d(track):
    """The 3D box: p_f near linear, a well's rise where it crosses the fault;
    returns the fault's pressure with the well."""
    plain, _ = run_track(track, box_scene())
    x, p, _, _ = cells(plain)
    linear = np.max(np.abs(p - (2.0e6 - DP * x / 4.0))) / DP
    check(linear <= 0.02, f"{track}: 3D: p_f linear to {linear:.2%} of dp (2 %: the two-point flux on triangles)")
    well, _ = run_track(track, box_scene(WELL3D))
    rise = cells(well)[1] - p
    centroids = fault_centroids(well)
    peak = centroids[np.argmax(rise)]
    check(np.hypot(peak[0] - 2.0, peak[1] - 0.5) <= 0.25, f"{track}: 3D: the well raises p_f most at "
          f"({peak[0]:.2f}, {peak[1]:.2f}), the cell it crosses at (2, 0.5), by {rise.max():.4g} Pa")
    return cells(well)[1]


runs, box = {}, {}
for track in ("C++", "prototype"):
    box[track] = check_3d(track)
    steady, _ = run_track(track, scene(CONDUIT.format(w=W)))
    check_linear_flow(steady, track)
    own, _ = run_track(track, scene(CONDUIT.format(w=W) + f"\npermeability = {K_F}"))
    check_linear_flow(own, track, f"the fault's own permeability {K_F:g} m^2", K_F * W)
    well, _ = run_track(track, scene(CONDUIT.format(w=W), left=1.0e6, well=WELL))
    check_well(well, track)
    two, _ = run_track(track, scene(CONDUIT.format(w=W)), ranks=2)
    ranks = max_difference(steady, two, ["pressure", "flux"], sort=True)
    one_rank, two_ranks = cells(steady), cells(two)
    order = [np.argsort(c[0]) for c in (one_rank, two_ranks)]
    fault = np.max(np.abs(one_rank[1][order[0]] - two_ranks[1][order[1]])) / DP
    check(max(ranks.values()) <= 1e-10 and fault <= 1e-10, f"{track}: 2 ranks give the fields of 1 rank: {ranks}, "
          f"the fault's pressure {fault:.1e} (1e-10)")
    transient_scene = scene(CONDUIT.format(w=W), c_f=C_F, end=1.0e-3, dt=1.0e-5, size=0.05)
    transient, _ = run_track(track, transient_scene, "output.every=2.5e-4")
    check_erfc(transient, track)
    check_filling(transient, track)
    restarted, step = killed_and_restarted(track, transient_scene, 50, "output.every=2.5e-4")
    same = max_difference(transient, restarted, ["pressure", "flux"])
    fault = np.max(np.abs(cells(transient)[1] - cells(restarted)[1])) / DP
    a, b = summary(transient)["fault_volumes"]["crack"], summary(restarted)["fault_volumes"]["crack"]
    volumes = max(abs(a[k] - b[k]) for k in a) / a["stored"]
    check(step < 100 and max(same.values()) <= 1e-12 and fault <= 1e-12 and volumes <= 1e-12,
          f"{track}: restarted at step {step}, the uninterrupted run's fields {same}, fault pressure ({fault:.1e}) "
          f"and volumes ({volumes:.1e}) (1e-12)")
    check_normal_permeability(track)
    check_fault_on_one_rank(track)
    conduit, _ = run_track(track, scene(CONDUIT.format(w=1.0e-9), permeability=1.0e-12))
    transparent, _ = run_track(track, scene('flow = "transparent"', permeability=1.0e-12))
    same = max_difference(conduit, transparent, ["pressure", "flux"])
    check(max(same.values()) <= 1e-6, f"{track}: a conduit far less conductive than the rock is transparent: "
          f"{same} (1e-6)")
    runs[track] = transient
tracks = max_difference(runs["C++"], runs["prototype"], ["pressure", "flux"])
fault = [cells(runs[track])[1] for track in runs]
with open(os.path.join(runs["C++"], "fault.xdmf")) as a, open(os.path.join(runs["prototype"], "fault.xdmf")) as b:
    same_xml = a.read() == b.read()
box_tracks = np.max(np.abs(box["C++"] - box["prototype"])) / DP
check(box_tracks <= 1e-10, f"3D: the prototype gives the C++ fault pressure to {box_tracks:.1e} of dp (1e-10)")
check(max(tracks.values()) <= 1e-10 and np.max(np.abs(fault[0] - fault[1])) <= 1e-10 * DP and same_xml,
      f"the prototype equals the C++ solver: {tracks}, the fault's pressure "
      f"{np.max(np.abs(fault[0] - fault[1])) / DP:.1e} of dp (1e-10), the same fault.xdmf: {same_xml}")
