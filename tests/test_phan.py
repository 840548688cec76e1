"""Friction on a crack inside the body (issue 38), both tracks: Phan et al.
(2003), a crack of half-length b = 1 m at psi = 20 degrees to a compression
sigma = 100 MPa (meshes/phan2d.geo), mu = tan 30 degrees, E = 25 GPa, nu =
0.25, plane strain: closed under sigma sin^2(psi), slipping along its
length by g_T(xi) = 4 (1 - nu^2)/E sigma sin(psi) (cos(psi) - sin(psi) mu)
sqrt(b^2 - (b - xi)^2). Asserted: the peak slip within 3 %, the l2 error
within 5 % over the inner 80 %, the normal traction within 1 %, every pair
on the bound (1e-9); mu = 0 is the frictionless run (1e-12), mu = 1000 the
uncut body (1e-10); summary.json's seismic moment G times the closed
form's potency within 3 % and fault.xdmf's exactly (1e-12), 0 when nothing
slips; prototype = C++ (1e-10)."""
import math
import os

import h5py
import numpy as np
from support import (PHAN_E, PHAN_NU, PHAN_PLATE, PHAN_SIGMA, check, fault_fields, max_difference, run_track,
                     summary, unsplit_difference, written)

E, NU, SIGMA, B = PHAN_E, PHAN_NU, PHAN_SIGMA, 1.0
PSI, THETA = math.radians(20), math.radians(30)
MU = math.tan(THETA)
ALONG = np.array([math.sin(PSI), math.cos(PSI), 0.0])   # the crack, from its lower tip up
NORMAL = np.array([-math.cos(PSI), math.sin(PSI)])
PLATE = PHAN_PLATE


def fault(friction):
    return f"[fault.crack]\n{friction}\nnormal = [{NORMAL[0]!r}, {NORMAL[1]!r}]\n"


def scene(text):
    return written(text)


def check_phan(out, track):
    x, _, series = fault_fields(out)
    fields = series[-1]
    xi = x @ ALONG + B
    exact = (4 * (1 - NU ** 2) / E * SIGMA * math.sin(PSI) * (math.cos(PSI) - math.sin(PSI) * MU)
             * np.sqrt(np.maximum(B ** 2 - (B - xi) ** 2, 0.0)))
    slip = np.linalg.norm(fields["slip"], axis=1)
    inner = np.abs(xi - B) <= 0.8 * B
    peak = slip.max() / exact.max() - 1
    check(abs(peak) <= 0.03, f"{track}: peak slip {slip.max():.6e} m, {100 * peak:+.2f} % of the closed form (3 %)")
    l2 = np.linalg.norm(slip[inner] - exact[inner]) / np.linalg.norm(exact[inner])
    check(l2 <= 0.05, f"{track}: relative l2 error of the slip over the inner 80 %: {100 * l2:.2f} % (5 %)")
    normal = fields["traction"][inner, 0]
    expected = SIGMA * math.sin(PSI) ** 2
    worst = np.abs(normal / expected - 1).max()
    check(worst <= 0.01, f"{track}: normal traction within {100 * worst:.2f} % of sigma sin^2(psi) (1 %)")
    pairs = fields["state"][:, 0] != 1  # the two tips are one node each: stuck
    check(np.all(fields["state"][pairs, 0] == 2), f"{track}: every pair slips ({int(pairs.sum())} pairs)")
    ratio = np.linalg.norm(fields["tangential_traction"], axis=1)[inner] / normal
    check(np.abs(ratio / MU - 1).max() <= 1e-9, f"{track}: |t_T| = mu t_N on the slipping pairs: "
          f"{np.abs(ratio / MU - 1).max():.1e} (1e-9)")


def moment(out):
    """summary.json's seismic moment of the crack, and G times the sum of
    fault.xdmf's |slip increment| times each pair's lumped length (half of
    its two segments)."""
    x, _, series = fault_fields(out, ("slip_increment",))
    with h5py.File(os.path.join(out, "fault.h5")) as f:
        segments = f["Mesh/topology"][:]
    lumped = np.zeros(len(x))
    np.add.at(lumped, segments.ravel(), np.repeat(np.linalg.norm(x[segments[:, 1]] - x[segments[:, 0]], axis=1) / 2, 2))
    fields = E / (2 * (1 + NU)) * np.sum(np.linalg.norm(series[-1]["slip_increment"], axis=1) * lumped)
    return summary(out)["seismic_moment"]["crack"]["total"], fields


def check_moment(track, slipping, stuck):
    """The seismic moment of the slipping crack and of the stuck one."""
    G = E / (2 * (1 + NU))
    exact = (G * 4 * (1 - NU ** 2) / E * SIGMA * math.sin(PSI) * (math.cos(PSI) - math.sin(PSI) * MU)
             * math.pi * B ** 2 / 2)
    total, fields = moment(slipping)
    held, _ = moment(stuck)
    check(abs(total / exact - 1) <= 0.03 and abs(total - fields) <= 1e-12 * total and abs(held) <= 1e-12 * total,
          f"{track}: seismic moment {total:.6e} N m/m, {100 * (total / exact - 1):+.2f} % of G times the closed "
          f"form's slip integral (3 %); G sum |slip increment| lumped to {abs(total - fields) / total:.1e} (1e-12); "
          f"{held:.1e} when mu = 1000")


runs = {}
for track in ("C++", "prototype"):
    frictional, _ = run_track(track, scene(PLATE + fault(f"friction = {MU!r}")))
    check_phan(frictional, track)
    runs[track] = frictional
    zero, _ = run_track(track, scene(PLATE + fault("friction = 0.0")))
    frictionless, _ = run_track(track, scene(PLATE + fault("")))
    same = max_difference(zero, frictionless, ["displacement"])
    check(same["displacement"] <= 1e-12, f"{track}: friction = 0 is the frictionless run: {same} (1e-12)")
    stuck, _ = run_track(track, scene(PLATE + fault("friction = 1000.0")))
    unsplit, _ = run_track(track, scene(PLATE))
    worst = unsplit_difference(stuck, unsplit, ["displacement"])
    check(worst["displacement"] <= 1e-10, f"{track}: mu = 1000 holds every pair: the run without the crack to "
          f"{worst['displacement']:.1e} (1e-10)")
    faults = summary(stuck)["contact"]["faults"]["crack"]
    check(faults["slipping"] == 0 and faults["stuck"] > 0, f"{track}: mu = 1000: stuck {faults['stuck']:.4f} m, "
          f"slipping {faults['slipping']}")
    check_moment(track, frictional, stuck)
tracks = max_difference(runs["C++"], runs["prototype"], ["displacement"])
check(tracks["displacement"] <= 1e-10, f"Phan's crack: the prototype equals the C++ solver: {tracks} (1e-10)")
