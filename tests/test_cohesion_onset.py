"""A cohesion-only fault under injection (issue 50, verification 4), on the C++
solver and the prototype: the conduit fault of scenes/fault_reactivation.toml
without friction (mu 0) and with cohesion c = 8.688 MPa, a well of 3e-4 m^2/s
into its centre for 30 days. The in-situ shear on the fault is 8.660 MPa; the
injection raises it by the well (to 8.690 MPa by day 30, the rock's poroelastic
stress), and the fault's bound is c whatever its normal traction.
- The same fault with c = 1 GPa (held everywhere) gives the shear the fault
  carries while it sticks. The cohesive fault sticks, its states the held
  one's, up to the first output where that shear reaches c, and slips from that
  output at the pair where it does.
- Every slipping pair carries |t_T| = c (1e-8), every stuck one less.
- The prototype gives the C++ fields to 1e-10."""
import numpy as np
from support import check, fault_fields, max_difference, run_track, scene, summary

COHESION = 8.688e6
INJECTION = ("well.injector.position=[0.0, 0.0]", 'well.injector.fault="fault"', "well.injector.rate=3.0e-4",
             "fault.fault.pore_pressure_load=false", 'fault.fault.flow="conduit"',
             "fault.fault.residual_aperture=1.0e-4", "fault.fault.friction=0.0", "time.end=2592000.0")
FIELDS = ["displacement", "pressure"]


def shear(f):
    return np.linalg.norm(f["tangential_traction"], axis=1)


def check_onset(track):
    held, _ = run_track(track, scene("fault_reactivation"), *INJECTION, "fault.fault.cohesion=1.0e9")
    out, _ = run_track(track, scene("fault_reactivation"), *INJECTION, f"fault.fault.cohesion={COHESION!r}")
    names = ("tangential_traction", "state")
    _, times, reference = fault_fields(held, names=names)
    _, _, series = fault_fields(out, names=names)
    reached = next(i for i, f in enumerate(reference) if shear(f).max() >= COHESION)
    first = next(i for i, f in enumerate(series) if np.any(f["state"][:, 0] == 2))
    where = int(np.argmax(shear(reference[reached])))
    check(summary(out)["converged"] is True and first == reached and series[first]["state"][where, 0] == 2,
          f"{track}: the fault sticks until day {times[first] / 86400:g}, the first output where the held fault's "
          f"shear reaches c ({shear(reference[reached]).max() / 1e6:.5f} MPa), and slips from there at that "
          f"pair ({reached} = {first})")
    slipping = np.concatenate([shear(f)[f["state"][:, 0] == 2] for f in series])
    stuck = np.concatenate([shear(f)[f["state"][:, 0] == 1] for f in series])
    on_bound = np.abs(slipping / COHESION - 1).max()
    check(on_bound <= 1e-8 and stuck.max() < COHESION, f"{track}: {slipping.size} slipping pair outputs at "
          f"|t_T| = c to {on_bound:.1e} (1e-8), the stuck ones below c (at most {stuck.max() / 1e6:.5f} MPa)")
    return held, out


def check_stuck_equal(held, out, track):
    """Before the onset both runs are the same run."""
    _, times, reference = fault_fields(held, names=("state",))
    _, _, series = fault_fields(out, names=("state",))
    same = all(np.array_equal(a["state"], b["state"]) for a, b in zip(reference, series)
               if not np.any(b["state"][:, 0] == 2))
    check(same, f"{track}: up to the onset the cohesive fault's states are the held fault's")


runs = {}
for track in ("C++", "prototype"):
    held, out = check_onset(track)
    check_stuck_equal(held, out, track)
    runs[track] = out
d = max_difference(runs["C++"], runs["prototype"], FIELDS)
check(max(d.values()) <= 1e-10, f"the prototype equals the C++ solver: {d} (1e-10)")
