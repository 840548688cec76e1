"""Barton-Bandis closure of a conduit fault (issue 39; docs/theory.md, "Flow
in a fault"), both tracks: test_conduit_fault's channel closed under 20 MPa,
w_h = w_r + V_m - V_m s_n / (K_ni V_m + s_n) with s_n = sigma - p_f, its
ends at 15 and 1 MPa, the rock impermeable. Steady: the flux the nonlinear
cubic law Q = int w_h(sigma - p)^3 dp / (12 mu_f L), p_f its profile and
each cell's w_h the closure at sigma - p_f, within 1 %; transient: the
volumes balance (1e-10 of the inflow); prototype = C++ (1e-10), 2 ranks =
1 and a restart ends equal; in 3D the closure to 1e-3 (median), p_f within
2 %, the flux within 4 % (the two-point flux on triangles), the Krylov
flow solve the factorisation's fields. Numbers: docs/verification.md."""
import os

import h5py
import numpy as np
from support import BOX_GEO, CHANNEL_GEO, check, killed_and_restarted, max_difference, run_track, summary, written

SIGMA, P_IN, P_OUT, W_R, V_M, K_NI, MU, L = 20.0e6, 15.0e6, 1.0e6, 1.0e-5, 1.0e-4, 1.0e11, 1.0e-3, 10.0
SCENE = f"""[mesh]
type = "gmsh"
file = "channel.geo"
dimension = 2
[mechanics]
E = 25.0e9
nu = 0.25
initial_equilibrium = true
[flow]
M = 1.0e10
c_f = 1.0e-9
mu_f = {MU}
permeability = 1.0e-25
initial_pressure = {P_OUT}
[coupling]
alpha = 1.0
tolerance = 1e-11
[time]
end = {{end}}
dt = {{dt}}
[boundary.bottom]
displacement = {{{{ y = 0.0 }}}}
[boundary.left]
displacement = {{{{ x = 0.0 }}}}
pressure = {P_IN}
[boundary.right]
pressure = {P_OUT}
[boundary.top]
traction = [0.0, {-SIGMA}]
[fault.crack]
normal = [0.0, 1.0]
flow = "conduit"
residual_aperture = {W_R}
closure = {{{{ V_m = {V_M}, K_ni = {K_NI} }}}}
"""
FIELDS = ["displacement", "pressure", "flux"]
# In 3D: the box of support.BOX_GEO, the mechanics holding it by rollers
# below, on the left and on the sides y = 0 and 1, the compression on top.
BOX = (SCENE.format(end=2.0e6, dt=1.0e6).replace('"channel.geo"', '"box.geo"')
       .replace("dimension = 2", "dimension = 3").replace("displacement = { y = 0.0 }", "displacement = { z = 0.0 }")
       .replace("traction = [0.0, -2", "traction = [0.0, 0.0, -2")
       .replace("normal = [0.0, 1.0]", "normal = [0.0, 0.0, 1.0]")
       + "[boundary.sides]\ndisplacement = { y = 0.0 }\n")


def closed_aperture(s_n):
    """w_h of the closed fault at the effective normal stress s_n."""
    return W_R + V_M - V_M * s_n / (K_NI * V_M + s_n)


def fault_cells(out):
    """Per output time the fault cells' pressure, hydraulic aperture and
    flux along the fault (x), the cells ordered by their centroid's x
    (fault.xdmf orders them by rank); and those x."""
    with h5py.File(os.path.join(out, "fault.h5")) as f:
        x, cells = f["Mesh/geometry"][:], f["Mesh/topology"][:]
        times = len(f["pressure"])
        series = [{name: f[f"{name}/{i}"][:][:, 0] for name in ("pressure", "hydraulic_aperture", "flux")}
                  for i in range(times)]
    centroid = x[cells].mean(axis=1)[:, 0]
    order = np.argsort(centroid)
    return centroid[order], [{k: v[order] for k, v in s.items()} for s in series]


def check_steady(track, out):
    x, series = fault_cells(out)
    cells = series[-1]
    p, w_h, q = cells["pressure"], cells["hydraulic_aperture"], cells["flux"]
    P = np.linspace(P_OUT, P_IN, 200001)
    g = closed_aperture(SIGMA - P) ** 3
    below = np.concatenate([[0.0], np.cumsum((g[1:] + g[:-1]) / 2 * np.diff(P))])  # int_{p_out}^{P}
    Q = below[-1] / (12 * MU * L)
    exact_p = np.interp(below[-1] - 12 * MU * Q * x, below, P)
    spread = np.ptp(q) / np.mean(q)
    check(spread <= 1e-6 and abs(np.mean(q) / Q - 1) <= 0.01,
          f"{track}: one flux along the fault to {spread:.1e} (1e-6), Q = {np.mean(q):.6e} m^2/s, the cubic law "
          f"integrated over the closure {Q:.6e} to {np.mean(q) / Q - 1:+.2e} (1 %)")
    profile = np.abs(p - exact_p).max() / (P_IN - P_OUT)
    aperture = np.abs(w_h / closed_aperture(SIGMA - p) - 1).max()
    check(profile <= 0.01 and aperture <= 0.01 and w_h.max() / w_h.min() > 1.5,
          f"{track}: p_f the closed form's profile to {profile:.2e} of the drop (1 %), w_h the closure at "
          f"sigma - p_f to {aperture:.2e} (1 %), from {w_h.min():.3e} to {w_h.max():.3e} m")


def check_box(track, out):
    """The 3D box: the closure at sigma - p_f in every cell, p_f's profile
    and the flux within the two-point flux's error on triangles
    (docs/theory.md, "Flow in a fault": 1.04 % of a linear p_f, the mean
    flux 2.6 % high)."""
    with h5py.File(os.path.join(out, "fault.h5")) as f:
        x, cells = f["Mesh/geometry"][:], f["Mesh/topology"][:]
        last = len(f["pressure"]) - 1
        p, w_h, q = (f[f"{name}/{last}"][:] for name in ("pressure", "hydraulic_aperture", "flux"))
    p, w_h = p[:, 0], w_h[:, 0]
    area = 0.5 * np.linalg.norm(np.cross(x[cells[:, 1]] - x[cells[:, 0]], x[cells[:, 2]] - x[cells[:, 0]]), axis=1)
    P = np.linspace(P_OUT, P_IN, 200001)
    g = closed_aperture(SIGMA - P) ** 3
    below = np.concatenate([[0.0], np.cumsum((g[1:] + g[:-1]) / 2 * np.diff(P))])
    Q = below[-1] / (12 * MU * 4.0)
    profile = np.abs(p - np.interp(below[-1] - 12 * MU * Q * x[cells].mean(axis=1)[:, 0], below, P)).max()
    aperture = np.abs(w_h / closed_aperture(SIGMA - p) - 1)
    mean = np.sum(q[:, 0] * area) / area.sum() / Q - 1
    check(np.median(aperture) <= 1e-3 and aperture.max() <= 0.02 and profile / (P_IN - P_OUT) <= 0.02
          and abs(mean) <= 0.04, f"{track}: 3D: w_h the closure at sigma - p_f to {np.median(aperture):.1e} "
          f"(median; 1e-3), {aperture.max():.1e} at most (2 %), p_f's profile to {profile / (P_IN - P_OUT):.2e} "
          f"(2 %), the mean flux the cubic law over the closure {mean:+.2%} (4 %)")
    return p


def check_volumes(track, out):
    v = summary(out)["fault_volumes"]["crack"]
    entered = abs(v["outflow"]) + abs(v["stored"])
    balance = abs(v["injected"] + v["exchanged"] - v["stored"] - v["outflow"]) / entered
    check(balance <= 1e-10 and v["stored"] > 0, f"{track}: injected + exchanged = stored + outflow to "
          f"{balance:.1e} (1e-10) of what entered; stored {v['stored']:.3e} m^2, outflow {v['outflow']:.3e} m^2")


def check_iterative_flow(track, path, direct):
    """The flow solved by the Krylov method (the fault's rows in its
    pressure split, solves to the coupling's inexact tolerance) against
    the factorisation."""
    out, _ = run_track(track, path, 'solver.flow="iterative"')
    fields, p_f = max_difference(out, direct, FIELDS), fault_pressure_difference(out, direct)
    check(max(fields.values()) <= 1e-5 and p_f <= 1e-9, f"{track}: 3D, the flow solved iteratively: the direct "
          f"solve's fields {fields} (1e-5) and fault pressure to {p_f:.1e} (1e-9)")


def fault_pressure_difference(a, b):
    """The largest difference of two runs' fault pressures over all output
    times (the same times checked), of p_in."""
    (_, sa), (_, sb) = fault_cells(a), fault_cells(b)
    check(len(sa) == len(sb), f"the same {len(sa)} fault outputs")
    return max(np.abs(s["pressure"] - t["pressure"]).max() for s, t in zip(sa, sb)) / P_IN


def main():
    """The steady and transient runs on both tracks, 2 ranks and a restart."""
    folder = os.path.dirname(written(CHANNEL_GEO, "channel.geo"))
    paths = {}
    for name, end, dt in (("steady", 2.0e6, 1.0e6), ("transient", 0.4, 0.05)):
        paths[name] = os.path.join(folder, f"{name}.toml")
        with open(paths[name], "w") as f:
            f.write(SCENE.format(end=end, dt=dt))
    runs = {}
    for track in ("C++", "prototype"):
        runs[track, "steady"], _ = run_track(track, paths["steady"])
        check_steady(track, runs[track, "steady"])
        runs[track, "transient"], _ = run_track(track, paths["transient"])
        check_volumes(track, runs[track, "transient"])
    for name in ("steady", "transient"):
        same = max_difference(runs["C++", name], runs["prototype", name], FIELDS)
        p_f = fault_pressure_difference(runs["C++", name], runs["prototype", name])
        check(max(same.values()) <= 1e-10 and p_f <= 1e-10,
              f"{name}: the prototype gives the C++ fields {same} and fault pressure to {p_f:.1e} (1e-10)")
    box = os.path.join(os.path.dirname(written(BOX_GEO, "box.geo")), "box.toml")
    with open(box, "w") as f:
        f.write(BOX)
    p_f = {}
    for track in ("C++", "prototype"):
        direct, _ = run_track(track, box)
        p_f[track] = check_box(track, direct)
        check_iterative_flow(track, box, direct)
    same = np.abs(p_f["C++"] - p_f["prototype"]).max() / P_IN
    check(same <= 1e-10, f"3D: the prototype gives the C++ fault pressure to {same:.1e} (1e-10)")
    one = runs["C++", "transient"]
    two, _ = run_track("C++", paths["transient"], ranks=2)
    p_f = fault_pressure_difference(one, two)
    check(p_f <= 1e-10, f"C++: 2 ranks give 1 rank's fault pressure to {p_f:.1e} (1e-10)")
    restarted, step = killed_and_restarted("C++", paths["transient"], 6)
    fields, p_f = max_difference(one, restarted, FIELDS), fault_pressure_difference(one, restarted)
    check(max(fields.values()) <= 1e-12 and p_f <= 1e-12, f"C++: restarted from step {step}, the uninterrupted fields "
          f"{fields} and fault pressure to {p_f:.1e} (1e-12)")


if __name__ == "__main__":
    main()
