"""The monolithic solve with a conduit fault's pressure p_f (issue 39;
docs/theory.md, "The monolithic solve with p_f"), both tracks: p_f appended
to (u, z, p), each step iterating on the apertures until they move by at
most the coupling's tolerance; each split's limit is its solution. On the
closure channel of test_fault_closure, the hydraulic opening of
test_hydraulic_opening and, in 3D, test_fault_closure's box with a
frictional fault: the split's fields and p_f (1e-9 / 1e-8), the volumes
balanced, no more solves than the split's iterations; 2D changes factorised,
3D ones preconditioned by the last factorisation (same fields); 2 ranks = 1,
a restart ends equal, prototype = C++; iterations.csv a row per solve; a
step whose apertures do not settle fails in one line. Numbers:
docs/verification.md."""
import os

import numpy as np
import test_hydraulic_opening as opening
from support import (BOX_GEO, CHANNEL_GEO, CRACK_GEO, INCLINED_CRACK_GEO, check, iterations, killed_and_restarted,
                     max_difference, run_track, summary, written)
from test_fault_closure import BOX, SCENE, fault_pressure_difference

FIELDS = ["displacement", "pressure", "flux"]
MONOLITHIC = 'coupling.scheme="monolithic"'


def check_volumes(label, out, tolerance=1e-10):
    v = summary(out)["fault_volumes"]["crack"]
    entered = abs(v["outflow"]) + abs(v["stored"]) + abs(v["exchanged"])
    balance = abs(v["injected"] + v["exchanged"] - v["stored"] - v["outflow"]) / entered
    check(balance <= tolerance, f"{label}: injected + exchanged = stored + outflow to {balance:.1e} ({tolerance:.0e})")


def same_runs(label, a, b, tolerance):
    fields, p_f = max_difference(a, b, FIELDS), fault_pressure_difference(a, b)
    check(max(fields.values()) <= tolerance and p_f <= tolerance,
          f"{label}: the fields {fields} and fault pressure to {p_f:.1e} ({tolerance:.0e})")


def solves(out):
    """The monolithic solves of a run, or the split's coupling iterations."""
    s = summary(out)
    return s["monolithic_solves"] or s["coupling_iterations"]


def opening_difference(a, b):
    """The largest difference of two runs of the opening crack: displacement
    (of its largest), and p_f (of S)."""
    fields = max_difference(a, b, ["displacement"])
    p_f = max(np.abs(s["pressure"] - t["pressure"]).max() / opening.S
              for s, t in zip(opening.fault_cells(a)[1], opening.fault_cells(b)[1]))
    return fields["displacement"], p_f


def check_opening(track):
    """The opening crack: the monolithic solve against the split, on the
    small square of INCLINED_CRACK_GEO (the same crack: it opens as in
    test_hydraulic_opening.py, whose closed forms need the large square)."""
    geo = written(INCLINED_CRACK_GEO, "crack.geo")
    path = written(opening.SCENE.replace("end = 1.5", "end = 0.75").replace(CRACK_GEO, geo))
    split, _ = run_track(track, path)
    monolithic, _ = run_track(track, path, MONOLITHIC)
    u, p_f = opening_difference(monolithic, split)
    counts = solves(monolithic), solves(split)
    check(u <= 1e-8 and p_f <= 1e-8 and counts[0] <= counts[1],
          f"{track}: the opening crack, monolithic against the split: displacement to {u:.1e}, p_f to {p_f:.1e} of "
          f"S (1e-8), in {counts[0]} solves against the split's {counts[1]} iterations (at most)")
    opening.check_volume(f"{track}: monolithic", *opening.fault_cells(monolithic))
    return monolithic


def against_split(track, path, label):
    """The monolithic run of a scene against its split run: the fields and
    p_f to 1e-9; the monolithic output."""
    split, _ = run_track(track, path)
    monolithic, _ = run_track(track, path, MONOLITHIC)
    same_runs(f"{track}: {label}, monolithic ({solves(monolithic)} solves) against the split ({solves(split)} "
              "iterations)", monolithic, split, 1e-9)
    return monolithic


def check_factorizations(track, path, run, dimension):
    """A monolithic run (`run`) against the same with every changed matrix
    factorised (-monolithic_ksp_type preonly): in 2D the same path (each
    change factorised), in 3D GMRES on the last factorisation, with fewer
    factorisations."""
    each, _ = run_track(track, path, MONOLITHIC, options=["-monolithic_ksp_type", "preonly"])
    a, b = (summary(out)["solvers"]["monolithic"] for out in (run, each))
    label = f"{track}: {dimension}D, the closure's {a['solves']} solves"
    if dimension == 2:
        check("preonly + lu (mumps), analysis by AMD" in a["method"] and a["factorizations"] >= a["solves"],
              f"{label} factorise each change, analysed by AMD: {a['factorizations']} times, "
              f"{a['linear_iterations']} back-solves ({a['method']!r})")
    else:
        check("gmres on the last factorisation" in a["method"] and a["factorizations"] < b["factorizations"],
              f"{label} factorise {a['factorizations']} times (GMRES on the last factorisation, "
              f"{a['linear_iterations']} iterations), {b['factorizations']} times with -monolithic_ksp_type preonly")
    # the method names the Krylov method the Newton steps run, not the
    # system's own preonly
    check("preonly + lu" in b["method"] and "gmres" not in b["method"],
          f"{track}: the method says which solve ran: {b['method']!r}")
    same_runs(f"{label}, against -monolithic_ksp_type preonly", run, each, 1e-10)


def rows_by_step(out):
    """iterations.csv's rows of each step."""
    steps = {}
    for r in iterations(out):
        steps.setdefault(int(r["step"]), []).append(r)
    return steps


def check_rows(label, out, reference=None):
    """A row per monolithic solve, numbered 1, 2, ... in each step, their
    Newton steps summing to the summary's; against `reference` (another
    run of the same case) the same rows and the first solve's changes."""
    s, steps = summary(out), rows_by_step(out)
    # Step 0 is the initial equilibrium's solve: a mechanics system's, whose
    # Newton steps are not the monolithic system's.
    steps.pop(0, None)
    every = [r for rows in steps.values() for r in rows]
    numbered = all([int(r["iteration"]) for r in rows] == list(range(1, len(rows) + 1)) for rows in steps.values())
    newton = sum(int(r["newton_steps"]) for r in every)
    check(len(every) == s["monolithic_solves"] and numbered and newton == s["solvers"]["monolithic"]["newton_iterations"]
          and all(not r["gamma"] for r in every),
          f"{label}: iterations.csv has a row per solve ({len(every)} in {len(steps)} steps, "
          f"{s['monolithic_solves']} solves), {newton} Newton steps as the summary's")
    if reference is None:
        return
    other = rows_by_step(reference)
    other.pop(0, None)
    shape = [len(r) for r in steps.values()] == [len(r) for r in other.values()]
    first = max(abs(float(a[k]) - float(b[k])) for a, b in zip(every, [r for rows in other.values() for r in rows])
                if a["iteration"] == "1" for k in ("dp_norm", "du_norm", "fault_dp_norm"))
    check(shape and first <= 1e-8, f"{label}: the same rows per step as the reference, the first solves' changes "
          f"to {first:.1e} (1e-8)")


def check_unsettled(track, path):
    """Apertures that do not settle in coupling.max_iterations = 2: exit 3,
    one line naming the last change, both iterations in iterations.csv."""
    out, p = run_track(track, path, MONOLITHIC, "coupling.max_iterations=2", expect=3)
    line = p.stderr.strip().splitlines()
    steps = rows_by_step(out)
    check(len(line) == 1 and "still move after 2 iterations" in line[0] and "p_f by" in line[0]
          and len(steps[max(steps)]) == 2 and summary(out)["status"] == "failed",
          f"{track}: unsettled apertures end in one line with the last change, both rows written: {line[-1][-170:]!r}")


def check_friction3d():
    """The 3D box, its fault frictional: the monolithic solve against the
    split, on both tracks; the prototype against C++."""
    coarse = BOX_GEO.replace("CharacteristicLengthMax = 0.25", "CharacteristicLengthMax = 0.5")
    path = os.path.join(os.path.dirname(written(coarse, "box.geo")), "box.toml")
    with open(path, "w") as f:
        f.write(BOX.replace('flow = "conduit"', 'flow = "conduit"\nfriction = 0.6')
                .replace("tolerance = 1e-11", "tolerance = 1e-13"))
    runs = {}
    for track in ("C++", "prototype"):
        runs[track] = against_split(track, path, "3D, friction and the closure")
        check_volumes(f"{track}: 3D, friction, monolithic", runs[track], 1e-7)
        check_factorizations(track, path, runs[track], 3)
    same_runs("3D, friction: the prototype against C++", runs["prototype"], runs["C++"], 1e-10)


def main():
    path = os.path.join(os.path.dirname(written(CHANNEL_GEO, "channel.geo")), "transient.toml")
    with open(path, "w") as f:
        f.write(SCENE.format(end=0.4, dt=0.05))
    runs = {}
    for track in ("C++", "prototype"):
        runs[track] = against_split(track, path, "the closure")
        check_volumes(f"{track}: monolithic, the closure", runs[track])
        check_factorizations(track, path, runs[track], 2)
        check_rows(f"{track}: the closure", runs[track], runs["C++"] if track == "prototype" else None)
        check_unsettled(track, path)
        runs[track, "opening"] = check_opening(track)
    same_runs("the closure: the prototype against C++", runs["prototype"], runs["C++"], 1e-10)
    u, p_f = opening_difference(runs["prototype", "opening"], runs["C++", "opening"])
    check(u <= 1e-10 and p_f <= 1e-10,
          f"the opening crack: the prototype gives the C++ displacement to {u:.1e} and p_f to {p_f:.1e} (1e-10)")
    check_friction3d()
    two, _ = run_track("C++", path, MONOLITHIC, ranks=2)
    same_runs("C++: 2 ranks against 1", two, runs["C++"], 1e-10)
    check_rows("C++: 2 ranks", two, runs["C++"])
    restarted, step = killed_and_restarted("C++", path, 6, MONOLITHIC)
    same_runs(f"C++: restarted from step {step}, against the uninterrupted run", restarted, runs["C++"], 1e-12)


if __name__ == "__main__":
    main()
