"""The fracture scenes (issue 13): a hydraulic fracture in the Barnett
Shale closing during production, 2D (scenes/fracture.toml) and 3D
(scenes/fracture3d.toml). Asserted:
- the coupling is weak (gamma < 0.1) and every step converges;
- the contact set grows during the drawdown from the tip alone to most of the
  face; in 2D the closed nodes are those beyond a front at every output;
- Signorini holds at every contact node and time with the scene's gap;
- started in equilibrium with the in-situ stresses, the far-field pressure
  does not jump in the first step (2 % without), and the monolithic run
  agrees with the split at every time, t = 0 included;
- the prototype gives the same fields and iterations (2D)."""
import subprocess

import numpy as np
from support import MPI_ENV, ROOT, Fields, check, check_signorini, max_difference, run, scene, summary

A, B, G0 = 15.0, 30.0, 0.005  # half-height, half-length, largest half-aperture (m)


def gap_2d(x):
    return G0 * np.maximum(0.0, 1 - (x[:, 0] / A) ** 2) ** (2 / 3)


def gap_3d(x):
    return G0 * np.maximum(0.0, 1 - (x[:, 0] / A) ** 2 - (x[:, 2] / B) ** 2) ** (2 / 3)


out, _ = run(scene("fracture"))
s = summary(out)
check(s["converged"] and s["gamma"] < 0.1, f"2D: converged, gamma = {s['gamma']:.3f} < 0.1")
counts = check_signorini(out, gap_2d, label="2D ", pressure_scale="run")
check(all(b >= a for a, b in zip(counts, counts[1:])), f"2D: the contact set never shrinks {counts}")
fracture_nodes = s["contact"]["contact_nodes"]
check(counts[1] == 1 and counts[-1] >= 0.9 * fracture_nodes,
      f"2D: from the tip alone to {counts[-1]} of {fracture_nodes} fracture nodes closed")

fields = Fields(out)
face = np.isclose(fields.nodes[:, 1], 0.0) & (fields.nodes[:, 0] <= A + 1e-9)
x = fields.nodes[face, 0]
for t in fields.times("contact_active")[1:]:
    closed = fields.at("contact_active", t)[face, 0] > 0.5
    front = x[closed].min()
    check(closed[x >= front].all(), f"2D t={t:g}: closed from the tip to x = {front:.2f} m, open for x < {front:.2f} m "
          f"({closed.sum()} nodes closed)")

def far_field_jump(directory):
    """Largest pressure change in the first step far from the fracture
    (x, y > 40 m), relative to the initial 27 MPa."""
    f = Fields(directory)
    times, far = f.times("pressure"), (f.cells[:, 0] > 40) & (f.cells[:, 1] > 40)
    return np.abs(f.at("pressure", times[1])[far] - f.at("pressure", times[0])[far]).max() / 2.7e7


jump = far_field_jump(out)
sudden, _ = run(scene("fracture"), "--set", "mechanics.initial_equilibrium=false")
jump_sudden = far_field_jump(sudden)
check(jump < 1e-4 < 1e-2 < jump_sudden, f"first step, far-field pressure change: {jump:.1e} of p0 from the "
      f"equilibrium, {jump_sudden:.1e} with the in-situ stresses applied at once")
mono, _ = run(scene("fracture"), "--set", "coupling.scheme=monolithic")
for name, d in max_difference(out, mono, ("displacement", "pressure", "contact_pressure")).items():
    check(d <= 1e-8, f"split vs monolithic, both from the initial equilibrium: {name} {d:.1e} <= 1e-8")

py = out + "-py"
p = subprocess.run(["/usr/bin/python3", "-m", "python_prototype", "run", scene("fracture"), "--out", py],
                   capture_output=True, text=True, cwd=ROOT, env=dict(MPI_ENV, PYTHONPATH=ROOT))
check(p.returncode == 0, f"the prototype runs the fracture scene ({p.stderr.strip()[-200:]!r})")
c = subprocess.run(["/usr/bin/python3", "-m", "python_prototype", "compare", out, py],
                   capture_output=True, text=True, cwd=ROOT, env=dict(MPI_ENV, PYTHONPATH=ROOT))
check(c.returncode == 0, "prototype and C++ agree on the fracture scene: " + c.stdout.strip().splitlines()[-1])

out3, _ = run(scene("fracture3d"))
s3 = summary(out3)
check(s3["converged"] and s3["gamma"] < 0.1, f"3D: converged, gamma = {s3['gamma']:.3f} < 0.1")
counts3 = check_signorini(out3, gap_3d, label="3D ", pressure_scale="run")
check(all(b >= a for a, b in zip(counts3, counts3[1:])) and counts3[-1] > 2 * counts3[1],
      f"3D: the contact set grows from {counts3[1]} (the rim) to {counts3[-1]} nodes")
