"""A contact solve that fails on the whole system is solved again on the
condensed one (issue 50; cpp/contact/contact_path.h, ContactPathChoice), on
the C++ solver and the prototype.

Phan's crack (scenes/phan.toml: half-length 1 m at 20 degrees to a
compression of 100 MPa; here mu = 0.6 and meshes/phan2d_coarse.geo) as a
conduit fault in an impermeable
rock, the load applied at once in the first step of the monolithic solve:
the coupled system with a conduit takes the full path by default, and its
semismooth Newton steps cycle there between two sets of states of the pairs
by the tips (closed and slipping with t_N > 0, and open: each state's exact
step lands in the other; docs/theory.md, "Friction").
- By default the failed solve is solved again condensed from the same
  start, and the run goes on condensed (the summary's method says so): exit
  0, the fields of `-monolithic_contact_condensed true` to 1e-10, and the
  split's (fixed-stress to 1e-10) to 1e-8 (C++);
- the path the user chooses is kept: `-monolithic_contact_condensed false`
  ends in one line (exit 3), the contact solver's;
- the prototype gives the C++ fields to 1e-10."""
from support import check, max_difference, run_track, scene, summary

# scenes/phan.toml's crack on its coarse mesh, mu 0.6, a conduit in an
# impermeable rock fed by a well at its middle, one step of 0.1 s
PHAN_CONDUIT = ["mesh.file=phan2d_coarse.geo", "flow.M=1.0e10", "flow.c_f=1.0e-9", "flow.mu_f=1.0e-3",
                "flow.permeability=1.0e-25", "flow.initial_pressure=0.0", "coupling.alpha=1.0",
                "coupling.tolerance=1e-10", "time.end=0.1", "time.dt=0.1", "fault.crack.friction=0.6",
                'fault.crack.flow="conduit"', "fault.crack.residual_aperture=1.0e-5", 'well.inj.fault="crack"',
                "well.inj.position=[0.0, 0.0]", "well.inj.rate=2.0e-7"]
FIELDS = ["displacement", "pressure"]
MONOLITHIC = [*PHAN_CONDUIT, 'coupling.scheme="monolithic"']
path = scene("phan")
default = {}
for track in ("C++", "prototype"):
    out, _ = run_track(track, path, *MONOLITHIC)
    default[track] = out
    method = summary(out)["solvers"]["monolithic"]["method"]
    check("after a full solve that did not converge" in method and summary(out)["converged"],
          f"{track}: the full solve failed and the condensed one converged ({method})")
    if track == "C++":
        condensed, _ = run_track(track, path, *MONOLITHIC, options=("-monolithic_contact_condensed", "true"))
        d = max_difference(out, condensed, FIELDS)
        check(max(d.values()) <= 1e-10, f"{track}: the condensed path's fields from the start: {d} (1e-10)")
        split, _ = run_track(track, path, *PHAN_CONDUIT)
        d = max_difference(out, split, FIELDS)
        check(max(d.values()) <= 1e-8, f"{track}: the split's fields: {d} (1e-8)")
    _, p = run_track(track, path, *MONOLITHIC, expect=3, options=("-monolithic_contact_condensed", "false"))
    lines = p.stderr.strip().splitlines()
    check(len(lines) == 1 and "contact solver" in lines[0] and "did not converge" in lines[0],
          f"{track}: the full path the user chose fails in one line: {p.stderr.strip()[-160:]!r}")
d = max_difference(default["C++"], default["prototype"], FIELDS)
check(max(d.values()) <= 1e-10, f"the prototype equals the C++ solver: {d} (1e-10)")
