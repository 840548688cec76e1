"""Friction through time (issue 38), both tracks, on test_phan's crack. Onset
by pressure: with cohesion 30 MPa and mu 0.6 the crack sticks (slip 0 to
round-off) until its given pressure p = 1 MPa/s t reaches p* = s_n - (tau -
c)/mu and slips, all at once, from the step that passes it; fault.xdmf's
slip_increment is each step's change of slip (1e-12). Hysteresis: loaded
and unloaded (mu 0.3) the crack keeps a residual slip, and a restart in
the unloading ends equal (1e-12). 2 ranks give 1 rank's states and fields
(1e-10); prototype = C++ (1e-10)."""
import math

import numpy as np
from support import PHAN_GEO, Fields, check, fault_fields, killed_and_restarted, max_difference, run_track, written

E, NU, SIGMA, CONFINEMENT = 25.0e9, 0.25, 1.0e8, 5.0e7
PSI = math.radians(20)
NORMAL = np.array([-math.cos(PSI), math.sin(PSI)])
MECHANICS = f"""[mesh]
type = "gmsh"
file = "{PHAN_GEO}"
dimension = 2
[mechanics]
E = {E}
nu = {NU}
[boundary.bottom]
displacement = {{ y = 0.0 }}
[boundary.left]
displacement = {{ x = 0.0 }}
"""
ONSET = MECHANICS + f"""[time]
end = 10.0
dt = 0.5
[boundary.top]
traction = [0.0, {-SIGMA}]
[fault.crack]
friction = 0.6
cohesion = 3.0e7
pressure = "1.0e6 * t"
normal = [{NORMAL[0]!r}, {NORMAL[1]!r}]
"""
HYSTERESIS = MECHANICS + f"""[time]
end = 2.0
dt = 0.125
[boundary.right]
traction = [{-CONFINEMENT}, 0.0]
[boundary.top]
traction = [0.0, "-{CONFINEMENT} - {SIGMA} * (t <= 1 ? t : 2 - t)"]
[fault.crack]
friction = 0.3
normal = [{NORMAL[0]!r}, {NORMAL[1]!r}]
"""


def scene(text):
    return written(text)


def check_onset(out, track):
    s_n, tau = SIGMA * math.sin(PSI) ** 2, SIGMA * math.sin(PSI) * math.cos(PSI)
    t_star = (s_n - (tau - 3.0e7) / 0.6) / 1.0e6
    _, times, series = fault_fields(out, ("slip", "slip_increment", "state"))
    largest = max(np.abs(f["slip"]).max() for f in series)
    increments = max(np.abs(b["slip_increment"] - (b["slip"] - a["slip"])).max() for a, b in zip(series, series[1:]))
    check(increments <= 1e-12 * largest, f"{track}: slip_increment is each step's change of slip to "
          f"{increments / largest:.1e} of the largest slip")
    # A stuck pair's slip is the round-off of the displacement solve: held
    # to 1e-14 of the largest displacement (relative to the largest slip it
    # was 1.9e-12 on an AVX-512 host's OpenBLAS kernel).
    fields = Fields(out)
    u_scale = max(np.abs(fields.at("displacement", t)).max() for t in fields.times("displacement"))
    for t, f in zip(times, series):
        state, slip = f["state"][:, 0], np.linalg.norm(f["slip"], axis=1).max()
        if t < t_star:
            check(np.all(state == 1) and slip <= 1e-14 * u_scale, f"{track}: t = {t:g} < t* = {t_star:.4f}: every "
                  f"pair stuck, slip {slip:.1e} m ({slip / u_scale:.1e} of the largest displacement, 1e-14)")
        else:
            check(np.count_nonzero(state == 2) == len(state) - 2, f"{track}: t = {t:g} > t* = {t_star:.4f}: every "
                  f"pair slips ({np.count_nonzero(state == 2)} of {len(state) - 2}), slip {slip:.3e} m")


runs = {}
for track in ("C++", "prototype"):
    onset, _ = run_track(track, scene(ONSET))
    check_onset(onset, track)
    hysteresis_scene = scene(HYSTERESIS)
    loaded, _ = run_track(track, hysteresis_scene)
    _, _, series = fault_fields(loaded)
    peak = max(np.linalg.norm(f["slip"], axis=1).max() for f in series)
    residual = np.linalg.norm(series[-1]["slip"], axis=1).max()
    check(residual >= 0.1 * peak, f"{track}: load taken off, the slip stays: {residual:.3e} m of the peak "
          f"{peak:.3e} m")
    restarted, _ = killed_and_restarted(track, hysteresis_scene, 11)
    same = max_difference(loaded, restarted, ["displacement"])
    check(same["displacement"] <= 1e-12, f"{track}: the restarted run is the uninterrupted one: {same} (1e-12)")
    runs[track] = (onset, loaded)
    two, _ = run_track(track, hysteresis_scene, ranks=2)
    states = [np.array_equal(a["state"], b["state"]) for a, b in zip(series, fault_fields(two)[2])]
    check(all(states), f"{track}: 2 ranks have 1 rank's stick/slip states at all {len(states)} output times")
    ranks = max_difference(loaded, two, ["displacement"], sort=True)
    check(ranks["displacement"] <= 1e-10, f"{track}: 2 ranks equal 1 rank: {ranks} (1e-10)")
for k, name in enumerate(("onset", "hysteresis")):
    tracks = max_difference(runs["C++"][k], runs["prototype"][k], ["displacement"])
    check(tracks["displacement"] <= 1e-10, f"{name}: the prototype equals the C++ solver: {tracks} (1e-10)")
