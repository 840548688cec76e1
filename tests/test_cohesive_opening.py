"""A cohesive fault opened along its whole length at once (issue 50; docs/
theory.md, "The bond"), both tracks: test_conduit_coupled's onset scene on
the coarse mesh to t = 1.4 s, where p_f passes the normal stress at every
pair at once (step 12). The monolithic solve completes: bonds hold until
then and break for good, none at an open pair; Coulomb's law holds (1e-10
of the load); the volumes balance (1e-8); condensed the same (1e-10); a
restart ends equal (1e-12); the prototype = C++ (1e-10). The split with
coupling.fallback hands step 12 to the monolithic scheme and ends as the
monolithic run (1e-8), the multirate split its last two windows; without
it, exit 3 at step 12, step 11 checkpointed; restarted from there
monolithic it ends as the monolithic run (1e-8), with coupling.fallback on
2 ranks as on 1 (1e-10). Numbers: docs/verification.md."""
import csv
import os
import shutil

import numpy as np
from support import (ROOT, Fields, check, fault_fields, killed_and_restarted, max_difference, restarted, run_track,
                     summary, written)
from test_conduit_coupled import COHESION, MU, ONSET, SIGMA

COARSE = os.path.join(ROOT, "meshes", "phan2d_coarse.geo")
SETS = ["time.end=1.4", 'coupling.scheme="monolithic"', f'mesh.file="{COARSE}"']
FAULT = ["state", "traction", "tangential_traction", "cohesion"]


def pair_fields(out):
    """Per output time the pairs' fields (but the tips) and the times."""
    x, times, series = fault_fields(out, FAULT)
    inner = np.linalg.norm(x[:, :2], axis=1) < 1 - 1e-9
    pairs = np.count_nonzero(inner)
    return times, [{k: v[inner].reshape(pairs, -1).squeeze() for k, v in f.items()} for f in series]


def same_states(a, b):
    """Whether two runs' pairs are in the same states at every output time."""
    return all(np.array_equal(s["state"], t["state"]) for s, t in zip(pair_fields(a)[1], pair_fields(b)[1]))


def check_bonds(track, out):
    """The bonds hold until the opening and break for good there."""
    times, series = pair_fields(out)
    cohesion = np.array([f["cohesion"] for f in series])
    state = np.array([f["state"] for f in series]).astype(int)
    broke = next((i for i, c in enumerate(cohesion) if np.any(c == 0)), None)
    held = broke is not None and np.all(cohesion[:broke] == COHESION)
    lasting = np.all(np.diff(cohesion, axis=0) <= 0) and set(np.unique(cohesion)) <= {0.0, COHESION}
    open_unbonded = np.all(cohesion[state == 0] == 0)
    check(held and times[broke] > 1.1 and lasting and open_unbonded and np.any(state[broke:] == 0),
          f"{track}: every bond holds until t = {times[broke - 1] if broke else '?'} s and "
          f"{int(np.sum(cohesion[broke] == 0)) if broke else 0} of {cohesion.shape[1]} break at t = "
          f"{times[broke] if broke else '?'} s, for good; the open pairs hold none")
    worst = slipping = 0.0
    for f in series:
        closed, slip = f["state"] > 0, f["state"] == 2
        bound = f["cohesion"] + MU * f["traction"]
        excess = np.linalg.norm(f["tangential_traction"], axis=1) - bound
        worst = max(worst, excess[closed].max(initial=-np.inf) / SIGMA)
        slipping = max(slipping, np.abs(excess[slip]).max(initial=0.0) / SIGMA)
    check(worst <= 1e-10 and slipping <= 1e-10,
          f"{track}: |t_T| <= cohesion + mu t_N at every closed pair ({worst:.1e} of the load over it at most), "
          f"on it at every slipping pair ({slipping:.1e}) (1e-10)")
    volumes = summary(out)["fault_volumes"]["crack"]
    balance = abs(volumes["injected"] + volumes["exchanged"] - volumes["stored"] - volumes["outflow"])
    check(summary(out)["converged"] and balance <= 1e-8 * volumes["injected"],
          f"{track}: converged; injected + exchanged - stored - outflow = {balance:.1e} m^2 of "
          f"{volumes['injected']:.1e} injected (1e-8)")
    return cohesion


runs, bonds = {}, {}
path = written(ONSET)
for track in ("C++", "prototype"):
    runs[track], _ = run_track(track, path, *SETS)
    bonds[track] = check_bonds(track, runs[track])
condensed, _ = run_track("C++", path, *SETS, options=["-monolithic_contact_condensed", "true"])
fields = max_difference(runs["C++"], condensed, ["displacement", "pressure"])
check(max(fields.values()) <= 1e-10 and same_states(runs["C++"], condensed)
      and np.array_equal(bonds["C++"], check_bonds("C++", condensed)),
      f"C++: condensed from the start, the same bonds and states, the fields {fields} (1e-10)")
resumed, step = killed_and_restarted("C++", path, 13, *SETS)
fields = max_difference(runs["C++"], resumed, ["displacement", "pressure"])
check(step == 12 and max(fields.values()) <= 1e-12 and np.array_equal(bonds["C++"], check_bonds("C++", resumed)),
      f"C++: restarted from step {step}, the uninterrupted fields {fields} (1e-12) and bonds")
fields = max_difference(runs["C++"], runs["prototype"], ["displacement", "pressure"])
check(max(fields.values()) <= 1e-10 and same_states(runs["C++"], runs["prototype"])
      and np.array_equal(bonds["C++"], bonds["prototype"]),
      f"the prototype equals the C++ solver: {fields} (1e-10), the same states and bonds")
# coupling.fallback = "monolithic" (docs/user-guide.md, "A step the split
# fails at"): the split hands step 12 to the monolithic scheme, from step
# 11, and goes on with the split at steps 13 and 14 (their iterations.csv
# rows are the split's: dsigma logged). It ends as the monolithic run
# (1e-8: the split's other steps met the coupling tolerance 1e-10) with the
# same bonds, Coulomb's law and balanced volumes (check_bonds), counting
# one fallback step; the prototype equals the C++ solver (1e-10).
FALLBACK = [s for s in SETS if "scheme" not in s] + ['coupling.fallback="monolithic"']


def split_steps(out):
    """The steps with a coupling iteration of the split in iterations.csv."""
    with open(os.path.join(out, "iterations.csv")) as f:
        return sorted({int(r["step"]) for r in csv.DictReader(f) if r["dsigma_norm"]})


fallback = {}
for track in ("C++", "prototype"):
    fallback[track], p = run_track(track, path, *FALLBACK)
    s = summary(fallback[track])
    fields = max_difference(runs[track], fallback[track], ["displacement", "pressure", "contact_pressure"])
    # the monolithic scheme's solves counted with the split's (summary.json's solvers)
    solvers = s["solvers"]
    check(set(solvers) == {"flow", "mechanics", "monolithic"} and s["monolithic_solves"] > 0
          and solvers["monolithic"]["solves"] == s["monolithic_solves"]
          and solvers["monolithic"]["newton_iterations"] > 0,
          f"{track}: summary.json counts the fallback's monolithic solves ({s['monolithic_solves']}) beside the "
          f"split's systems ({sorted(solvers)})")
    check(s["converged"] and s["steps"] == 14 and s["fallback_steps"] == 1 and s["fallback"] == "monolithic"
          and "step 12 (t = 1.2)" in p.stdout and "the monolithic scheme solves the step (coupling.fallback)" in p.stdout
          and split_steps(fallback[track]) == list(range(1, 15)),
          f"{track}: with coupling.fallback the split's run hands step 12 to the monolithic scheme and takes steps 13 "
          f"and 14 itself ({s['steps']} steps, {s['fallback_steps']} fallback step, split iterations at steps "
          f"{split_steps(fallback[track])})")
    check(max(fields.values()) <= 1e-8 and np.array_equal(bonds[track], check_bonds(track, fallback[track])),
          f"{track}: with coupling.fallback the monolithic run's fields {fields} (1e-8) and bonds")
fields = max_difference(fallback["C++"], fallback["prototype"], ["displacement", "pressure", "contact_pressure"])
check(max(fields.values()) <= 1e-10 and same_states(fallback["C++"], fallback["prototype"]),
      f"with coupling.fallback the prototype equals the C++ solver: {fields} (1e-10), the same states")
# The multirate split (q = 2) with coupling.fallback (issue 50 item 2: the
# opening in every scheme): its windows ending at t = 1.2 and 1.4 do not
# converge (sublinear, as the single-rate split's step 12), and the
# monolithic scheme solves each window's two fine steps, its rows in
# iterations.csv the window's; every fine flow step written, bonds,
# Coulomb's law and volumes as above (check_bonds), the prototype equal to
# the C++ solver (1e-10).
MULTIRATE = FALLBACK + ["coupling.scheme=multirate", "coupling.q=2"]
multirate = {}
for track in ("C++", "prototype"):
    multirate[track], p = run_track(track, path, *MULTIRATE)
    s = summary(multirate[track])
    with open(os.path.join(multirate[track], "iterations.csv")) as f:
        monolithic_rows = {(r["step"], round(float(r["time"]), 9)) for r in csv.DictReader(f) if not r["dsigma_norm"]}
    check(s["converged"] and s["steps"] == 7 and s["fallback_steps"] == 2
          and monolithic_rows == {("6", 1.1), ("6", 1.2), ("7", 1.3), ("7", 1.4)}
          and len(Fields(multirate[track]).times("pressure")) == 15,
          f"{track}: multirate with coupling.fallback: {s['steps']} windows, {s['fallback_steps']} solved by the "
          f"monolithic scheme, its rows {sorted(monolithic_rows)}")
    check_bonds(track, multirate[track])
fields = max_difference(multirate["C++"], multirate["prototype"], ["displacement", "pressure", "contact_pressure"])
check(max(fields.values()) <= 1e-10, f"multirate with coupling.fallback: the prototype equals the C++ solver: {fields}")
# The split at that step (docs/user-guide.md, "Friction"): its iterations
# converge sublinearly (the fault's ratio toward 1), and both tracks end in
# exit 3 at step 12 after 100 iterations with the steps before kept, their
# error proposing the monolithic scheme. (The C++ contact solve of the
# second iteration passes by continuation in the load since 2026-12-04;
# before, it failed there, BondFailure.)
# A failed step writes the checkpoint of the last completed one (output.
# checkpoint_every = 5: steps 5 and 10 by the schedule, 11 at the failure),
# and a restart may change coupling.scheme: the split's run goes on
# monolithic from step 11 and ends as the monolithic run (1e-8: the split's
# steps before met the coupling tolerance 1e-10 at rates up to 0.96).
SPLIT = [s for s in SETS if "scheme" not in s] + ["output.checkpoint_every=5", "solver.cells_per_rank=0"]
for track in ("C++", "prototype"):
    out, p = run_track(track, path, *SPLIT, expect=3)
    s = summary(out)
    # the steps it converged: the coupled residual 1.7e-7 of their fluid
    # content's terms (0.997 of their fluid content's change before
    # 2026-12-04: undrained, the terms cancel)
    check(s["max_coupled_residual"] <= 1e-5, f"{track}: the split's converged steps' coupled residual "
          f"{s['max_coupled_residual']:.1e} of the change of their fluid content's terms (1e-5)")
    check(s["status"] == "failed" and s["steps"] == 11 and not s["converged"] and "step 12" in s["failure"]
          and 'coupling.scheme = "monolithic"' in p.stderr and f"step 11 is in the checkpoint (--restart {out} --set coupling.scheme=monolithic goes on" in p.stderr,
          f"{track}: the split ends at step 12 ({s['status']}, {s['steps']} steps kept) proposing the "
          f"monolithic scheme, step 11 checkpointed: {p.stderr.strip()[-160:]!r}")
    # coupling.fallback may change at a restart too: the failed run goes on
    # from step 11 with it, on 2 ranks, and ends as the 1-rank run that had
    # it from the start. Whether a failed solve breaks bonds (the monolithic
    # solve of step 12) is decided on every rank alike, also on a rank that
    # owns no pair: it skipped the collective, and the ranks waited on each
    # other for ever there until 2026-12-04.
    two = out + "-2-ranks"
    shutil.copytree(out, two)
    p = restarted(track, path, two, *SPLIT, 'coupling.fallback="monolithic"', ranks=2)
    fields = max_difference(fallback[track], two, ["displacement", "pressure", "contact_pressure"])
    check("restarted from the checkpoint at step 11" in p.stdout and summary(two)["fallback_steps"] == 1
          and summary(two)["converged"] and max(fields.values()) <= 1e-10 and same_states(fallback[track], two),
          f"{track}: restarted from step 11 with coupling.fallback on 2 ranks, it ends as the 1-rank run that had "
          f"it: {fields} (1e-10), the same states")
    # The restart may choose the monolithic system's solver too.
    p = restarted(track, path, out, *SPLIT, 'coupling.scheme="monolithic"', 'solver.monolithic="direct"')
    fields = max_difference(runs[track], out, ["displacement", "pressure"])
    check("restarted from the checkpoint at step 11" in p.stdout and summary(out)["converged"]
          and summary(out)["scheme"] == "monolithic" and max(fields.values()) <= 1e-8,
          f"{track}: restarted from step 11 with the monolithic scheme by its direct solver, it ends as the "
          f"monolithic run: {fields} (1e-8)")
