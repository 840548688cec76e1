"""Flow through boundaries (issue 22, item 3), both tracks: `flux = expr`
prescribes the outward normal Darcy flux, `rate = expr` the total rate
through a planar boundary spread uniformly. A steady column (2D and 3D)
and a layered column without storage give the exact linear and piecewise
linear pressure and flux (1e-10); a rate R is the flux it stands for
(1e-12); in a closed column what entered equals the fluid content at every
step (1e-10: flow alone, monolithic, split); split = monolithic under a
time-dependent injection, prototype = C++; a rate varying along the
boundary, a flux on a curved boundary and two flow conditions on one
boundary are refused in one line."""
import os
import subprocess

import numpy as np

from support import PROTOTYPE, ROOT, TRACKS, Fields, check, fluid_content, poroelastic_column, run_track, written

MU, K, Q_IN, H = 1.0e-3, 1.0e-12, 1.0e-6, 10.0


def column(dimension, base, storage_modulus="1.0e11", mechanics=""):
    mesh = ('type = "rectangle"\nupper = [2.0, 10.0]\ncells = [2, 20]' if dimension == 2 else
            'type = "box"\nupper = [1.0, 1.0, 10.0]\ncells = [1, 1, 10]')
    return f"""[scene]
name = "column"
description = "flow through the base of a column"
[mesh]
{mesh}
{mechanics}
[flow]
M = {storage_modulus}
mu_f = {MU}
permeability = {K}
[time]
end = 1.0e4
dt = 1.0e3
[boundary.bottom]
{base}
"""


def steady_column(track, dimension):
    out, _ = run_track(track, written(column(dimension, f"flux = {-Q_IN}") + "[boundary.top]\npressure = 0.0\n"))
    fields = Fields(out)
    t = fields.times("pressure")[-1]
    height = fields.cells[:, dimension - 1]
    exact = MU * Q_IN / K * (H - height)
    p = fields.at("pressure", t)[:, 0]
    z = fields.at("flux", t)
    error_p = np.max(np.abs(p - exact)) / np.max(exact)
    upward = np.zeros(3)
    upward[dimension - 1] = Q_IN
    error_z = np.max(np.abs(z - upward)) / Q_IN
    check(error_p < 1e-10 and error_z < 1e-10, f"{track}, {dimension}D: the steady column's pressure and flux equal "
          f"the exact solution (relative errors {error_p:.2e}, {error_z:.2e})")
    return out


def layered_column(track):
    """Flux in at the base, p = 0 on top, three layers; p(y) = mu q times the
    sum over the layers above y of their thickness over k."""
    layers = [(0.0, 3.0, 1.0e-12), (3.0, 6.0, 1.0e-15), (6.0, 10.0, 1.0e-13)]
    k = "y < 3 ? 1.0e-12 : (y < 6 ? 1.0e-15 : 1.0e-13)"
    text = column(2, f"flux = {-Q_IN}", storage_modulus="inf")
    text = text.replace(f"permeability = {K}", f'permeability = "{k}"')
    out, _ = run_track(track, written(text + "[boundary.top]\npressure = 0.0\n"))
    fields = Fields(out)
    t = fields.times("pressure")[-1]
    y = fields.cells[:, 1]
    exact = np.zeros_like(y)
    for bottom, top, permeability in layers:
        exact += MU * Q_IN / permeability * np.clip(top - np.maximum(y, bottom), 0.0, None)
    p, z = fields.at("pressure", t)[:, 0], fields.at("flux", t)
    error_p = np.max(np.abs(p - exact)) / np.max(exact)
    error_z = np.max(np.abs(z - [0.0, Q_IN, 0.0])) / Q_IN
    check(error_p < 1e-10 and error_z < 1e-10, f"{track}: the layered column's pressure and flux equal the exact "
          f"piecewise-linear solution (relative errors {error_p:.2e}, {error_z:.2e})")


def mass_balance(track, label, extra, alpha, tolerance, *sets):
    """A closed column fed through its base of width 2 at the rate 2e-6 t."""
    out, _ = run_track(track, written(column(2, 'rate = "2.0e-6 * t / 1.0e4"', "1.0e9", extra)), *sets)
    fields = Fields(out)
    worst = 0.0
    for t in fields.times("pressure")[1:]:
        # Backward Euler: the discrete injection is the sum of dt R(t_n).
        injected = sum(2.0e-6 * s / 1.0e4 * 1.0e3 for s in np.arange(1.0e3, t + 1.0, 1.0e3))
        worst = max(worst, abs(np.sum(fluid_content(fields, t, 1.0e-9, alpha)) - injected) / injected)
    check(worst < tolerance, f"{track}, {label}: the fluid content equals the volume injected through the base at "
          f"every step (largest relative difference {worst:.2e} < {tolerance:g})")
    return out


MECHANICS = poroelastic_column("top")

results = {}
for track in TRACKS:
    results[track, 2] = steady_column(track, 2)
    results[track, 3] = steady_column(track, 3)
    layered_column(track)
    flux_run, _ = run_track(track, written(column(2, f"flux = {-Q_IN}") + "[boundary.top]\npressure = 0.0\n"))
    rate_run, _ = run_track(track, written(column(2, f"rate = {2 * Q_IN}") + "[boundary.top]\npressure = 0.0\n"))
    c = subprocess.run(PROTOTYPE + ["compare", flux_run, rate_run, "--tolerance", "1e-12"], capture_output=True,
                       text=True, cwd=ROOT)
    check(c.returncode == 0, f"{track}: rate 2e-6 through a base of width 2 is flux -1e-6 to 1e-12")
    mass_balance(track, "flow alone", "", 0.0, 1e-10)
    results[track, "monolithic"] = mass_balance(track, "monolithic", MECHANICS, 0.8, 1e-10,
                                                "coupling.scheme=monolithic")
    results[track, "split"] = mass_balance(track, "fixed-stress split", MECHANICS, 0.8, 1e-10)

for key in [2, 3, "monolithic", "split"]:
    c = subprocess.run(PROTOTYPE + ["compare", results["C++", key], results["prototype", key], "--tolerance", "1e-10"],
                       capture_output=True, text=True, cwd=ROOT)
    check(c.returncode == 0, f"{key}: the prototype gives the C++ fields ({c.stdout.strip().splitlines()[-1]})")
c = subprocess.run(PROTOTYPE + ["compare", results["C++", "split"], results["C++", "monolithic"], "--tolerance",
                                "1e-6"], capture_output=True, text=True, cwd=ROOT)
check("pressure" in c.stdout and all(" ok" in line for line in c.stdout.splitlines() if "max relative" in line),
      "the split and the monolithic solve agree under the injection to 1e-6:\n" + c.stdout)

# Bad input: each one line naming the key, exit 2, on both tracks.
CURVED = os.path.join(ROOT, "scenes", "hertz_poroelastic.toml")
for label, scene_file, sets, key in [
        ("a rate that varies along the boundary", written(column(2, 'rate = "1e-6 * x"')), [], "boundary.bottom.rate"),
        ("flux and rate on one boundary", written(column(2, "flux = 1e-6\nrate = 1e-6")), [], "boundary.bottom.rate"),
        ("pressure and rate on one boundary", written(column(2, "pressure = 0.0\nrate = 1e-6")), [],
         "boundary.bottom.rate"),
        ("a NaN flux", written(column(2, 'flux = "sqrt(-x-1)"')), [], "boundary.bottom.flux"),
        ("a flux on a curved boundary", CURVED, ["boundary.arc.flux=-1e-6"], "boundary.arc.flux")]:
    for track in TRACKS:
        _, p = run_track(track, scene_file, *sets, expect=2)
        check(len(p.stderr.strip().splitlines()) == 1 and key in p.stderr,
              f"{track}, {label}: one line naming {key}: {p.stderr.strip()!r}")
