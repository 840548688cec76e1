"""The mass balance of a conduit fault and the rock (issue 39, item 3;
docs/theory.md "Flow in a fault"), on the C++ solver and the prototype: a well
injects R = 1e-6 m^2/s into the middle of a conduit crack (half-length 1 m at
30 degrees, residual aperture 1e-4 m, c_f = 1e-8 1/Pa) that leaks into a
closed 4 m square of rock (1e-14 m^2, 1/M = 1e-9 1/Pa).
- Rigid walls and a poroelastic rock (alpha = 1, 1 MPa on top, coupling
  tolerance 1e-12): at every output R t is the fault's stored fluid plus the
  change of the rock's content (S p + alpha div u) to 1e-10 of it.
- summary.json's fault_volumes: injected R t, stored and exchanged as the
  fields give them (the rock's content is minus the exchanged volume), and
  injected + exchanged = stored + outflow with no outflow, to 1e-10.
- Killed after 6 steps, restarted from step 4 (C++): the volumes to 1e-12."""
import os

import h5py
import numpy as np
from support import (INCLINED_CRACK_GEO, Fields, check, fluid_content, killed_and_restarted, run_track, summary,
                     written)

RATE, W_R, C_F, STORAGE = 1.0e-6, 1.0e-4, 1.0e-6, 1.0e-9
FLOW = f"""[mesh]
type = "gmsh"
file = "crack.geo"
dimension = 2
[flow]
M = {1 / STORAGE}
c_f = {C_F}
mu_f = 1.0e-3
permeability = 1.0e-15
initial_pressure = 0.0
[time]
end = 0.8
dt = 0.1
[fault.crack]
normal = [-0.5, 0.8660254037844386]
flow = "conduit"
residual_aperture = {W_R}
[well.inj]
fault = "crack"
position = [0.0, 0.0]
rate = {RATE}
"""
MECHANICS = """[mechanics]
G = 3.0e9
lambda = 2.0e9
[coupling]
alpha = 1.0
tolerance = 1e-12
max_iterations = 200
[boundary.left]
displacement = { x = 0.0 }
[boundary.bottom]
displacement = { y = 0.0 }
[boundary.top]
traction = [0.0, -1.0e6]
"""


def fault_stored(out):
    """Per output time the fluid the fault stores since the start: the
    opening's volume sum |k| (w_h - w_h^0) and the compression sum c_f w_h
    |k| (p - p^old), step by step (every step is an output here)."""
    with h5py.File(os.path.join(out, "fault.h5")) as f:
        x, cells = f["Mesh/geometry"][:], f["Mesh/topology"][:]
        n = len(f["pressure"])
        p = [f[f"pressure/{i}"][:].ravel() for i in range(n)]
        w = [f[f"hydraulic_aperture/{i}"][:].ravel() for i in range(n)]
    lengths = np.linalg.norm(x[cells[:, 1]] - x[cells[:, 0]], axis=1)
    stored = [0.0]
    for i in range(1, n):
        stored.append(stored[-1] + np.sum(lengths * (w[i] - w[i - 1]) + C_F * w[i] * lengths * (p[i] - p[i - 1])))
    return stored


def check_balance(track, label, out, alpha):
    """Injected = fault stored + the rock's content, at every output."""
    fields, stored = Fields(out), fault_stored(out)
    times = fields.times("pressure")
    worst = 0.0
    for t, fault in zip(times[1:], stored[1:]):
        rock = np.sum(fluid_content(fields, t, STORAGE, alpha))
        worst = max(worst, abs(fault + rock - RATE * t) / (RATE * t))
    rock_share = np.sum(fluid_content(fields, times[-1], STORAGE, alpha)) / (RATE * times[-1])
    check(worst <= 1e-10 and abs(rock_share) > 0.01,
          f"{track} ({label}): injected = fault stored + the rock's content to {worst:.1e} of the injected (1e-10) "
          f"at {len(times) - 1} outputs; the rock's content changed by {rock_share:.1%} of the injected")
    v = summary(out)["fault_volumes"]["crack"]
    injected = RATE * times[-1]
    rock = np.sum(fluid_content(fields, times[-1], STORAGE, alpha))
    errors = [abs(v["injected"] - injected), abs(v["stored"] - stored[-1]), abs(v["exchanged"] + rock),
              abs(v["injected"] + v["exchanged"] - v["stored"] - v["outflow"]), abs(v["outflow"])]
    check(max(errors) <= 1e-10 * injected,
          f"{track} ({label}): summary.json's volumes: injected {v['injected']:.6e}, stored {v['stored']:.6e}, "
          f"exchanged {v['exchanged']:.6e}, outflow {v['outflow']:.1e}, as the fields give them and balanced to "
          f"{max(errors) / injected:.1e} of the injected (1e-10)")
    return v


folder = os.path.dirname(written(INCLINED_CRACK_GEO, "crack.geo"))
scenes = {"rigid walls": (FLOW, 0.0), "poroelastic": (FLOW + MECHANICS, 1.0)}
for label, (text, alpha) in scenes.items():
    path = os.path.join(folder, f"{label.replace(' ', '_')}.toml")
    with open(path, "w") as f:
        f.write(text)
    for track in ("C++", "prototype"):
        out, _ = run_track(track, path)
        volumes = check_balance(track, label, out, alpha)
    if alpha > 0:
        restarted, step = killed_and_restarted("C++", path, 6)
        again = summary(restarted)["fault_volumes"]["crack"]
        run_volumes = summary(run_track("C++", path)[0])["fault_volumes"]["crack"]
        difference = max(abs(again[k] - run_volumes[k]) for k in again) / run_volumes["injected"]
        check(difference <= 1e-12, f"C++ ({label}): killed after step 6 and restarted from step {step}, the "
              f"volumes are the uninterrupted run's to {difference:.1e} (1e-12)")
