"""The monolithic contact solve of a frictional conduit fault loaded at once
(issue 50: one Newton solve that never stalls; cpp/contact/convergence.h,
contact_path.h), both tracks: Phan's crack (mu 0.6, phan2d_coarse.geo) as a
conduit in an impermeable rock fed by a well, the load applied in the first
monolithic step. It converges on the full path (mass balances within their
round-off no longer jitter), with the condensed path's fields (1e-10) and
the split's (1e-8); with cohesion 30 MPa the cycle by the tips stops and
the clamped start solves it (< 30 Newton steps); a full solve that fails
(held to one Newton step) goes on condensed, the summary says so, the
fields the condensed path's (1e-10), and with the condensed path refused
it ends in one line (exit 3); prototype = C++ (1e-10). Until 2026-12-03
both ended in exit 3 (docs/theory.md, "Friction"; docs/verification.md)."""
from support import check, iterations, max_difference, run_track, scene, summary

# scenes/phan.toml's crack on its coarse mesh, mu 0.6, a conduit in an
# impermeable rock fed by a well at its middle, one step of 0.1 s
PHAN_CONDUIT = ["mesh.file=phan2d_coarse.geo", "flow.M=1.0e10", "flow.c_f=1.0e-9", "flow.mu_f=1.0e-3",
                "flow.permeability=1.0e-25", "flow.initial_pressure=0.0", "coupling.alpha=1.0",
                "coupling.tolerance=1e-10", "time.end=0.1", "time.dt=0.1", "fault.crack.friction=0.6",
                'fault.crack.flow="conduit"', "fault.crack.residual_aperture=1.0e-5", 'well.inj.fault="crack"',
                "well.inj.position=[0.0, 0.0]", "well.inj.rate=2.0e-7"]
FIELDS = ["displacement", "pressure"]
MONOLITHIC = [*PHAN_CONDUIT, 'coupling.scheme="monolithic"']
CONDENSED, FULL, CAPPED = (("-monolithic_contact_condensed", "true"), ("-monolithic_contact_condensed", "false"),
                           ("-monolithic_snes_max_it", "1"))
path = scene("phan")


def method(out):
    return summary(out)["solvers"]["monolithic"]["method"]


def same_fields(a, b, bound, what):
    d = max_difference(a, b, FIELDS)
    check(max(d.values()) <= bound, f"{what}: {d} ({bound:g})")


default = {}
for track in ("C++", "prototype"):
    out, _ = run_track(track, path, *MONOLITHIC)
    default[track] = out
    check("(full)" in method(out) and summary(out)["converged"],
          f"{track}: converged on the full path ({method(out)})")
    condensed, _ = run_track(track, path, *MONOLITHIC, options=CONDENSED)
    same_fields(out, condensed, 1e-10, f"{track}: the condensed path's fields")
    if track == "C++":
        split, _ = run_track(track, path, *PHAN_CONDUIT)
        same_fields(out, split, 1e-8, f"{track}: the split's fields")
    cohesive, _ = run_track(track, path, *MONOLITHIC, "fault.crack.cohesion=3.0e7")
    steps = sum(int(r["newton_steps"]) for r in iterations(cohesive))
    check("(full)" in method(cohesive) and steps < 30,
          f"{track}: with cohesion, on the full path in {steps} Newton steps (the cycle stopped; < 30)")
    rescued, _ = run_track(track, path, *MONOLITHIC, options=CAPPED)
    check("after a full solve that did not converge" in method(rescued),
          f"{track}: capped, the failed full solve went on condensed ({method(rescued)})")
    same_fields(rescued, condensed, 1e-10, f"{track}: capped, the condensed path's fields")
    _, p = run_track(track, path, *MONOLITHIC, expect=3, options=CAPPED + FULL)
    lines = p.stderr.strip().splitlines()
    check(len(lines) == 1 and "contact solver" in lines[0] and "did not converge" in lines[0],
          f"{track}: capped on the full path the user chose, one line: {p.stderr.strip()[-160:]!r}")
same_fields(default["C++"], default["prototype"], 1e-10, "the prototype equals the C++ solver")
