"""A conduit fault in the multirate split (issue 39; docs/theory.md, "Flow in
a fault"), both tracks: q flow steps per mechanics step, p_f carried fine
step by fine step with 1/q of the window's aperture change and the fault's
fixed-stress term in the fine-step form. test_fault_closure's channel: q =
1 equals "fixed-stress" (1e-12); without closure and alpha = 0, q = 2
equals the single-rate split on the fine steps (1e-10), balanced; with the
closure the split converges slowly, the fault's ratios between 0.9 and
0.99 (the zero-sum fine-step modes damped by L/(L + S):
docs/multirate-two-pass.md), balanced; the two-pass split reaches the
printed scheme's fixed point (1e-8) in at most a fifth of the iterations;
the prototype = C++ (1e-10). Numbers: docs/verification.md."""
import csv
import os

import numpy as np
from support import CHANNEL_GEO, check, max_difference, run_track, summary, written
from test_fault_closure import SCENE, fault_cells, fault_pressure_difference

FIELDS = ["displacement", "pressure", "flux"]
FLOW = ["pressure", "flux"]  # written at every fine step; the displacement once per window
MULTIRATE = ['coupling.scheme="multirate"', "coupling.max_iterations=1000"]


def same_runs(label, a, b, tolerance):
    fields, p_f = max_difference(a, b, FIELDS), fault_pressure_difference(a, b)
    check(max(fields.values()) <= tolerance and p_f <= tolerance,
          f"{label}: the fields {fields} and fault pressure to {p_f:.1e} ({tolerance:.0e})")


def same_fine_steps(label, multirate, fine, q):
    """The multirate run against the single-rate one on its fine steps: the
    flow fields at every fine step, the fault pressure at the windows' ends
    (fault.xdmf is written with the mechanics, once per window)."""
    fields = max_difference(multirate, fine, FLOW)
    (_, a), (_, b) = fault_cells(multirate), fault_cells(fine)
    b = b[::q]
    check(len(a) == len(b), f"{label}: {len(a)} fault outputs, one per window")
    p_f = max(np.abs(s["pressure"] - t["pressure"]).max() for s, t in zip(a, b)) / 15.0e6
    check(max(fields.values()) <= 1e-10 and p_f <= 1e-10,
          f"{label}: the flow fields {fields} and fault pressure to {p_f:.1e} (1e-10)")


def check_volumes(label, out):
    v = summary(out)["fault_volumes"]["crack"]
    entered = abs(v["outflow"]) + abs(v["stored"]) + abs(v["exchanged"])
    balance = abs(v["injected"] + v["exchanged"] - v["stored"] - v["outflow"]) / entered
    check(balance <= 1e-10, f"{label}: injected + exchanged = stored + outflow to {balance:.1e} (1e-10)")


def check_two_pass(track, two_pass, multirate):
    """The second pass damps the fine-step modes the first leaves: the
    printed scheme's fixed point in far fewer iterations."""
    fields, p_f = max_difference(two_pass, multirate, FIELDS), fault_pressure_difference(two_pass, multirate)
    iterations = [summary(out)["coupling_iterations"] for out in (two_pass, multirate)]
    check(max(fields.values()) <= 1e-8 and p_f <= 1e-8 and 5 * iterations[0] <= iterations[1],
          f"{track}: with the closure, q = 2, two-pass gives multirate's fields {fields} and fault pressure to "
          f"{p_f:.1e} (1e-8: the same fixed point) in {iterations[0]} iterations against {iterations[1]} "
          "(at most a fifth)")
    check_volumes(f"{track}: two-pass, the closure", two_pass)


def fault_ratios(out):
    with open(os.path.join(out, "iterations.csv")) as f:
        return np.array([float(r["fault_ratio"]) for r in csv.DictReader(f) if r["fault_ratio"]])


folder = os.path.dirname(written(CHANNEL_GEO, "channel.geo"))
path = os.path.join(folder, "closure.toml")
with open(path, "w") as f:
    f.write(SCENE.format(end=0.1, dt=0.05))
closed = os.path.join(folder, "closed.toml")
with open(closed, "w") as f:
    f.write(SCENE.format(end=0.2, dt=0.025).replace("alpha = 1.0", "alpha = 0.0")
            .replace("closure = {", "# closure = {"))
runs = {}
for track in ("C++", "prototype"):
    single, _ = run_track(track, path)
    one, _ = run_track(track, path, *MULTIRATE, "coupling.q=1")
    same_runs(f"{track}: multirate with q = 1 against fixed-stress", one, single, 1e-12)
    fine, _ = run_track(track, closed)
    runs[track, "closed"], _ = run_track(track, closed, *MULTIRATE, "coupling.q=2", "time.dt=0.025")
    same_fine_steps(f"{track}: a closed fault the rock does not feel, q = 2 against fixed-stress on the fine "
                    "steps", runs[track, "closed"], fine, 2)
    check_volumes(f"{track}: q = 2, closed", runs[track, "closed"])
    runs[track, "closure"], _ = run_track(track, path, *MULTIRATE, "coupling.q=2", "time.dt=0.025")
    check_volumes(f"{track}: q = 2, the closure", runs[track, "closure"])
    ratios, single_ratios = fault_ratios(runs[track, "closure"]), fault_ratios(single)
    check(0.9 <= np.median(ratios) <= 0.99 and single_ratios.max() <= 0.5,
          f"{track}: the fault's ratios with the closure, q = 2: median {np.median(ratios):.3f} (0.9 to 0.99: "
          f"L/(L + S)), single-rate at most {single_ratios.max():.3f} (0.5)")
    runs[track, "two-pass"], _ = run_track(track, path, *MULTIRATE, "coupling.q=2", "time.dt=0.025",
                                           'coupling.scheme="multirate-two-pass"')
    check_two_pass(track, runs[track, "two-pass"], runs[track, "closure"])
for name in ("closed", "closure", "two-pass"):
    same_runs(f"{name}, q = 2: the prototype against C++", runs["prototype", name], runs["C++", name], 1e-10)
