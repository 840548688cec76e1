"""Jansen and Meulenbroek's displaced fault (issue 37), on the C++ solver and the
prototype: scenes/fault_depletion.toml, a reservoir offset by a vertical
frictionless fault, depleted by 25 MPa in four steps (a given pore pressure, no
flow), plane strain. The fault's slip u_y(0+) - u_y(0-) is the closed-form
trapezoid: (1 - 2 nu) alpha |dp| / G (b - a) on |y| < a, falling linearly to 0
at |y| = b, 0 beyond; within 5 % of that plateau at every pair outside one cell
(2 m) of the reservoir's corners y = +-a, +-b. The fault stays closed, and with
every pair in contact the problem is linear: the slip at each step is t/4 of
the last one. The prototype gives the C++ fields to 1e-10. On 2 and 3 ranks
(C++) and 2 (prototype) the fields equal one rank's to 1e-10 with the same
pairs in contact, the partitioner cutting along the fault (a pair's two nodes
on two ranks, its block of the change of variables spanning them)."""
import numpy as np
from support import Fields, check, fault_pairs, max_difference, run_track, scene

E, NU, ALPHA, DP, A, B = 14.95e9, 0.15, 0.9, -25.0e6, 75.0, 150.0
G = E / (2 * (1 + NU))
PLATEAU = (1 - 2 * NU) * ALPHA * abs(DP) / G * (B - A)


def closed_form(y):
    y = np.abs(y)
    return np.where(y <= A, PLATEAU, np.where(y <= B, PLATEAU * (B - y) / (B - A), 0.0))


runs = {}
for track in ("C++", "prototype"):
    out, _ = run_track(track, scene("fault_depletion"))
    runs[track] = out
    fields = Fields(out)
    plus, minus = fault_pairs(fields, [1.0, 0.0])
    y = fields.nodes[plus, 1]
    times = fields.times("displacement")
    slips = {t: fields.at("displacement", t)[plus, 1] - fields.at("displacement", t)[minus, 1] for t in times}
    final = slips[times[-1]]
    away = np.min(np.abs(np.abs(y)[:, None] - np.array([A, B])[None, :]), axis=1) > 2.0
    error = np.abs(final - closed_form(y))[away].max() / PLATEAU
    check(error <= 0.05, f"{track}: slip within {error:.2%} of the plateau {PLATEAU:.4f} m at {away.sum()} of "
          f"{len(y)} pairs (limit 5 %)")
    middle = np.argmin(np.abs(y))
    check(abs(final[middle] - PLATEAU) <= 0.05 * PLATEAU,
          f"{track}: slip {final[middle]:.4f} m at the middle vs {PLATEAU:.4f} m")
    t_last = times[-1]
    t = fields.times("contact_active")[-1]
    active = fields.at("contact_active", t)[plus, 0]
    opening = np.abs(fields.at("displacement", t)[plus, 0] - fields.at("displacement", t)[minus, 0]).max()
    check(np.all(active > 0.5) and opening <= 1e-12,
          f"{track}: the fault stays closed ({int(np.sum(active > 0.5))} of {len(y)} pairs in contact, "
          f"largest opening {opening:.1e} m)")
    linear = max(np.abs(slips[t] - t / t_last * final).max() for t in times if t > 0) / PLATEAU
    check(linear <= 1e-8, f"{track}: the slip grows linearly with the depletion (to {linear:.1e})")

differences = max_difference(runs["C++"], runs["prototype"], ["displacement", "contact_pressure"])
check(max(differences.values()) <= 1e-10, f"prototype = C++: {differences} (limit 1e-10)")

for track, ranks in (("C++", 2), ("C++", 3), ("prototype", 2)):
    out, _ = run_track(track, scene("fault_depletion"), ranks=ranks)
    differences = max_difference(runs[track], out, ["displacement", "contact_pressure", "contact_active"])
    check(max(differences.values()) <= 1e-10 and differences["contact_active"] == 0,
          f"{track} on {ranks} ranks = 1 rank: {differences} (limit 1e-10, the same pairs in contact)")
