"""A contact face loaded by the pore pressure beside it: with
`pore_pressure_load = true` the total traction -p n of a fracture whose fluid
is in pressure equilibrium with the rock beside it, so that the contact
pressure is the fracture's effective normal stress; both tracks, split and
monolithic.
- Equal set-ups: with the pore pressure held at p0 everywhere (in equilibrium
  from the start: mechanics.initial_equilibrium, the same pressure on the
  drained boundary, nothing changing in time), the face loaded by the pore
  pressure gives the run of the face loaded by the traction p0 (displacement,
  contact pressure and sets to 1e-10).
- A transient run: the converged split equals the monolithic solve.
- Bad input: the key without contact or without flow is one line naming it."""
from support import TRACKS, check, max_difference, run_track, scene, written

P0 = 400.0  # Pa: below the top load of 1e3 Pa, so the face stays in contact
with open(scene("default")) as f:
    DEFAULT = f.read()
HELD = (DEFAULT.replace("alpha = 1.0\n", "alpha = 0.8\n")
        .replace("nu = 0.2\n", "nu = 0.2\ninitial_equilibrium = true\n")
        .replace("permeability = 1.0e-13    # m^2\n", f"permeability = 1.0e-13    # m^2\ninitial_pressure = {P0}\n")
        .replace("pressure = 0.0\n", f"pressure = {P0}\n"))
assert HELD.count(str(P0)) == 2, "the default scene changed: update this test"
CONTACT = "contact = { gap = 0.0012, normal = [0.0, -1.0] }   # m\n"
by_pore = written(HELD.replace(CONTACT, CONTACT + "pore_pressure_load = true\n"))
by_traction = written(HELD.replace(CONTACT, CONTACT + f"traction = [0.0, {P0}]\n"))
NAMES = ["displacement", "contact_pressure", "contact_active", "pressure"]

runs = {}
for track in TRACKS:
    for scheme in ("fixed-stress", "monolithic"):
        sets = ("time.end=1.0", f"coupling.scheme={scheme}", "boundary.bottom.contact.gap=0.0")
        pore, _ = run_track(track, by_pore, *sets)
        traction, _ = run_track(track, by_traction, *sets)
        worst = max_difference(pore, traction, NAMES)
        check(max(worst.values()) < 1e-10, f"{track}, {scheme}: the pore pressure p0 on the face acts as the "
              f"traction p0 ({', '.join(f'{k} {v:.1e}' for k, v in worst.items())})")
        runs[track, scheme] = pore

# (The flux of this held state is round-off: not compared.)
for scheme in ("fixed-stress", "monolithic"):
    worst = max_difference(runs["C++", scheme], runs["prototype", scheme], NAMES)
    check(max(worst.values()) < 1e-12, f"{scheme}: the prototype gives the C++ fields to 1e-12 "
          f"({', '.join(f'{k} {v:.1e}' for k, v in worst.items())})")

# A transient run: the held block drains through its top (p0 -> 0) while
# its base stays pressed on the foundation; the converged split equals the
# monolithic solve, so the face term enters the split's pressure load and
# the coupled operator alike.
transient = written(HELD.replace(CONTACT, CONTACT + "pore_pressure_load = true\n")
                    .replace(f"# Pa\npressure = {P0}\n", "# Pa\npressure = 0.0\n"))
assert "initial_pressure = 400.0" in open(transient).read() and "pressure = 0.0" in open(transient).read()
for track in TRACKS:
    sets = ("time.end=2.4", "boundary.bottom.contact.gap=0.0")
    split, _ = run_track(track, transient, *sets, "coupling.tolerance=1e-11")
    coupled, _ = run_track(track, transient, *sets, "coupling.scheme=monolithic")
    worst = max_difference(split, coupled, ["displacement", "pressure", "contact_active"])
    check(max(worst.values()) < 1e-7, f"{track}: split and monolithic agree with the face loaded "
          f"({', '.join(f'{k} {v:.1e}' for k, v in worst.items())})")

for label, text, sets, key in (
        ("on a boundary without contact", DEFAULT, ["boundary.top.pore_pressure_load=true"],
         "boundary.top.pore_pressure_load"),
        ("in a scene without flow", open(scene("elastic_contact")).read(), [], "pore_pressure_load")):
    path = written(text)
    if not sets:
        boundary = [line for line in text.splitlines() if "contact = {" in line][0]
        path = written(text.replace(boundary, boundary + "\npore_pressure_load = true"))
    for track in TRACKS:
        _, p = run_track(track, path, *sets, expect=2)
        check(len(p.stderr.strip().splitlines()) == 1 and key in p.stderr,
              f"{track}: a pore pressure load {label} is one line naming {key}: {p.stderr.strip()!r}")
