"""A fully open crack with friction (issue 50, verification 1), on the C++ solver
and the prototype: Phan's crack (test_phan.py: half-length b = 1 m at psi = 20
degrees to a compression sigma = 100 MPa, E = 25 GPa, nu = 0.25, plane strain)
with Coulomb friction mu = tan(30 degrees) and a fluid pressure p = 50 MPa on
its faces, above the normal stress s_n = sigma sin^2(psi) = 11.7 MPa: every
pair opens (but the tips, one node each), and an open pair carries no traction,
friction none either. The jumps are Sneddon's mode I and mode II,
    opening = 4 (1 - nu^2)/E (p - s_n) sqrt(b^2 - s^2),
    slip    = 4 (1 - nu^2)/E tau      sqrt(b^2 - s^2),   tau = sigma sin(psi) cos(psi),
within 2 % at the centre (measured -0.42 % and -0.44 %) and 5 % in l2 over the
inner 80 %; the frictionless run gives the same fields (1e-12); the prototype
gives the C++ fields (1e-10)."""
import math

import numpy as np
from support import (PHAN_E, PHAN_NU, PHAN_PLATE, PHAN_SIGMA, check, fault_fields, max_difference, run_track,
                     written)

E, NU, SIGMA, B, P = PHAN_E, PHAN_NU, PHAN_SIGMA, 1.0, 5.0e7
PSI, MU = math.radians(20), math.tan(math.radians(30))
NORMAL = np.array([-math.cos(PSI), math.sin(PSI)])
ALONG = np.array([math.sin(PSI), math.cos(PSI), 0.0])  # the crack, from its lower tip up


def crack(friction):
    return written(PHAN_PLATE + f"""[fault.crack]
friction = {friction!r}
pressure = {P!r}
normal = [{NORMAL[0]!r}, {NORMAL[1]!r}]
""")


def check_sneddon(out, track):
    x, _, series = fault_fields(out, names=("slip", "opening", "state"))
    f = series[-1]
    xi = x @ ALONG + B
    shape = 4 * (1 - NU ** 2) / E * np.sqrt(np.maximum(B ** 2 - (B - xi) ** 2, 0.0))
    s_n, tau = SIGMA * math.sin(PSI) ** 2, SIGMA * math.sin(PSI) * math.cos(PSI)
    inner, centre = np.abs(xi - B) <= 0.8 * B, int(np.argmin(np.abs(xi - B)))
    tips = np.abs(xi - B) >= B - 1e-9
    check(np.all(f["state"][~tips, 0] == 0), f"{track}: all {np.sum(~tips)} pairs but the tips open")
    for name, jump, load in (("opening", f["opening"][:, 0], P - s_n),
                             ("slip", np.linalg.norm(f["slip"], axis=1), tau)):
        exact = shape * load
        at_centre = jump[centre] / exact[centre] - 1
        l2 = np.linalg.norm(jump[inner] - exact[inner]) / np.linalg.norm(exact[inner])
        check(abs(at_centre) <= 0.02 and l2 <= 0.05, f"{track}: the {name} is Sneddon's for "
              f"{load / 1e6:.2f} MPa: {100 * at_centre:+.2f} % at the centre (2 %), l2 {100 * l2:.2f} % over the "
              f"inner 80 % (5 %)")


runs = {}
for track in ("C++", "prototype"):
    out, _ = run_track(track, crack(MU))
    check_sneddon(out, track)
    frictionless, _ = run_track(track, crack(0.0))
    d = max_difference(out, frictionless, ["displacement"])
    check(d["displacement"] <= 1e-12, f"{track}: open, friction changes nothing: the frictionless run to "
          f"{d['displacement']:.1e} (1e-12)")
    runs[track] = out
d = max_difference(runs["C++"], runs["prototype"], ["displacement"])
check(d["displacement"] <= 1e-10, f"the prototype equals the C++ solver: {d} (1e-10)")
