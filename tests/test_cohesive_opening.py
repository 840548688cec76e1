"""A cohesive fault opened along its whole length at once (issue 50; docs/
theory.md, "The contact law", the bond), on the C++ solver and the
prototype: test_conduit_coupled's onset scene (Phan's crack with mu = 0.6
and a cohesion c = 30 MPa, a conduit in an impermeable rock fed by a well)
on the coarse mesh, in the monolithic solve, run on past t = 1.2 s, where
p_f passes the normal stress at every pair at once. Until the bond, the
contact solve cycled there between the pairs closed and pulled (their bound
c) and open (bound 0) and the run ended in exit 3 at step 12.
- The run completes; its cohesion field (fault.xdmf) is c at every pair
  until t = 1.1 s and breaks, never to return, at the step where a pair's
  effective normal traction reaches zero; an open pair holds none.
- Coulomb's law with each pair's own cohesion at every output time: at a
  closed pair |t_T| <= cohesion + mu t_N, on it where the pair slips (to
  1e-10 of the load).
- The conduit's volumes balance: injected + exchanged = stored (1e-8).
- Which bonds break does not depend on the path: condensed from the start
  (-monolithic_contact_condensed true) the same bonds and states, the
  fields to 1e-10 (C++).
- Killed after step 13 and restarted from its checkpoint of step 12 (the
  broken bonds in it), the run ends with the uninterrupted fields and
  cohesions (1e-12; C++).
- The prototype gives the C++ fields to 1e-10, the same states and bonds."""
import os

import numpy as np
from support import ROOT, check, fault_fields, killed_and_restarted, max_difference, run_track, summary, written
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
restarted, step = killed_and_restarted("C++", path, 13, *SETS)
fields = max_difference(runs["C++"], restarted, ["displacement", "pressure"])
check(step == 12 and max(fields.values()) <= 1e-12 and np.array_equal(bonds["C++"], check_bonds("C++", restarted)),
      f"C++: restarted from step {step}, the uninterrupted fields {fields} (1e-12) and bonds")
fields = max_difference(runs["C++"], runs["prototype"], ["displacement", "pressure"])
check(max(fields.values()) <= 1e-10 and same_states(runs["C++"], runs["prototype"])
      and np.array_equal(bonds["C++"], bonds["prototype"]),
      f"the prototype equals the C++ solver: {fields} (1e-10), the same states and bonds")
