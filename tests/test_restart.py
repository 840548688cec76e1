"""Checkpoint and restart (issue 12): a run with output.checkpoint_every = 3
stopped mid-run (SIGTERM, which also writes a checkpoint, or SIGKILL, which
leaves the last periodic one) and continued with --restart DIR ends with the
uninterrupted run's fields (to the bit: docs/user-guide.md promises it), output
times, iterations.csv and summary counts (a restart factorises again and forms
the Schur complement again: those counts differ), for the single-rate,
multirate, two-pass multirate and monolithic schemes with contact, with
backward Euler and with BDF2 (whose memory, the state one step back, the
checkpoint keeps) with time.adaptive (the same steps after the restart) and
with coupling.q = "auto" (the same windows); the prototype does the same. A
restart of another scene, or of a directory without a checkpoint, is refused."""
import json
import os
import re
import signal
import subprocess
import sys
import tempfile

from support import BINARY, MPI_ENV, ROOT, check, scene

sys.path.insert(0, ROOT)
from python_prototype.output.compare import compare  # noqa: E402

PROTOTYPE = ["/usr/bin/python3", "-m", "python_prototype"]
ENV = dict(MPI_ENV, PYTHONPATH=ROOT)
CHECKPOINT = ["--set", "output.checkpoint_every=3"]
# A restarted run sets its preconditioners up again (factorisations, AMG).
EXPECTED_TO_DIFFER = {"factorizations", "preconditioner_setups", "schur_columns", "schur_factorizations",
                      "contact_factorizations"}


def counts(summary, prefix=""):
    """The summary's counts and results, without times."""
    flat = {}
    for key, value in summary.items():
        if isinstance(value, dict):
            flat.update(counts(value, prefix + key + "."))
        elif "time" not in key and not prefix.startswith("timings") and key.split(".")[-1] not in EXPECTED_TO_DIFFER:
            flat[prefix + key] = value
    return flat


def stopped_run(exe, options, number, steps=5):
    """A run stopped by `number` once `steps` steps are printed; its directory."""
    out = tempfile.mkdtemp(prefix="restart-")
    p = subprocess.Popen(exe + ["run", scene("default"), "--out", out] + options, stdout=subprocess.PIPE,
                         stderr=subprocess.PIPE, text=True, env=ENV)
    printed = 0
    for line in p.stdout:
        printed += re.match(r"step +\d+/", line) is not None  # a completed step, not a retry's line
        if printed == steps:
            p.send_signal(number)
            break
    p.communicate(timeout=300)
    return out, p.returncode


def run(exe, *arguments):
    return subprocess.run(exe + list(arguments), capture_output=True, text=True, env=ENV, timeout=600)


# 16 steps, stopped after 5: the contact set still grows after the restart
# (until step 11).
SHORT = ["--set", "time.end=3.2"]


def shortened(options):
    """A run of 16 steps, or 8 windows of q = 4 (the multirate schemes print
    a line per window), or 24 steps with q = auto (whose windows change and
    retry after the stop); time.adaptive as given."""
    if "time.adaptive.tolerance=1e-2" in options:
        return options
    if "coupling.q=auto" in options:
        return ["--set", "time.end=4.8"] + options
    return (["--set", "time.end=6.4"] if "coupling.q=4" in options else SHORT) + options


ADAPTIVE = ["--set", "time.end=4.8", "--set", "time.adaptive.tolerance=1e-2", "--set", "output.every=1.2"]
Q_AUTO = ["--set", "coupling.scheme=multirate", "--set", "coupling.q=auto"]
CASES = [("single rate", BINARY, ["--set", "mesh.cells=[80,8]"], signal.SIGTERM),
         ("single rate after SIGKILL", BINARY, ["--set", "mesh.cells=[80,8]"], signal.SIGKILL),
         ("multirate", BINARY, ["--set", "coupling.scheme=multirate", "--set", "coupling.q=4"], signal.SIGTERM),
         ("two-pass multirate", BINARY, ["--set", "coupling.scheme=multirate-two-pass", "--set", "coupling.q=4"],
          signal.SIGTERM),
         ("monolithic", BINARY, ["--set", "coupling.scheme=monolithic", "--set", "mesh.cells=[80,8]"],
          signal.SIGTERM),
         ("prototype, single rate", "prototype", [], signal.SIGTERM),
         # BDF2 reads the state one step before the restart's: the checkpoint keeps it.
         ("single rate, BDF2", BINARY, ["--set", "mesh.cells=[80,8]", "--set", "time.scheme=bdf2"], signal.SIGTERM),
         ("multirate, BDF2", BINARY, ["--set", "coupling.scheme=multirate", "--set", "coupling.q=4", "--set",
                                      "time.scheme=bdf2"], signal.SIGTERM),
         ("monolithic, BDF2", BINARY, ["--set", "coupling.scheme=monolithic", "--set", "time.scheme=bdf2"],
          signal.SIGTERM),
         ("prototype, single rate, BDF2", "prototype", ["--set", "time.scheme=bdf2"], signal.SIGTERM),
         # time.adaptive: the grid as planned, the accepted states and the
         # controller's memory are in the checkpoint: the same steps follow.
         ("single rate, adaptive BDF2", BINARY, ADAPTIVE + ["--set", "time.scheme=bdf2"], signal.SIGTERM),
         ("monolithic, adaptive", BINARY, ADAPTIVE + ["--set", "coupling.scheme=monolithic"], signal.SIGKILL),
         ("prototype, single rate, adaptive BDF2", "prototype", ADAPTIVE + ["--set", "time.scheme=bdf2"],
          signal.SIGTERM),
         # coupling.q = "auto": the last window's q, its change of u and the
         # limit of the next q are in the checkpoint: the same windows follow.
         ("multirate, q = auto", BINARY, Q_AUTO, signal.SIGKILL),
         ("multirate, q = auto, BDF2", BINARY, Q_AUTO + ["--set", "time.scheme=bdf2"], signal.SIGTERM),
         ("prototype, two-pass multirate, q = auto", "prototype",
          ["--set", "coupling.scheme=multirate-two-pass", "--set", "coupling.q=auto"], signal.SIGTERM)]
for label, exe, options, number in CASES:
    exe = PROTOTYPE if exe == "prototype" else [exe]
    options = shortened(options) + CHECKPOINT
    whole = tempfile.mkdtemp(prefix="whole-")
    p = run(exe, "run", scene("default"), "--out", whole, *options)
    check(p.returncode == 0, f"{label}: the uninterrupted run ({p.stderr.strip()[-200:]})")
    out, status = stopped_run(exe, options, number)
    check(status in (128 + number, -number), f"{label}: stopped by {signal.Signals(number).name} ({status})")
    p = run(exe, "run", scene("default"), "--restart", out, *options)
    check(p.returncode == 0 and "restarted from the checkpoint at step" in p.stdout,
          f"{label}: the restart runs to the end ({p.stderr.strip()[-200:]})")
    lines = []
    agreed = compare(whole, out, tolerance=0.0, out=lines.append) == 0
    check(agreed, f"{label}: the same fields at every output time to the bit, same coupling iterations: {lines[-1]}")
    with open(os.path.join(whole, "iterations.csv")) as a, open(os.path.join(out, "iterations.csv")) as b:
        check(a.read() == b.read(), f"{label}: the same iterations.csv")
    with open(os.path.join(whole, "summary.json")) as a, open(os.path.join(out, "summary.json")) as b:
        sa, sb = counts(json.load(a)), counts(json.load(b))
    differing = sorted(k for k in sa if sa[k] != sb.get(k))
    check(not differing, f"{label}: the same summary counts ({len(sa)} compared; differing: {differing})")

# Refusals: another scene, no checkpoint.
out, _ = stopped_run([BINARY], SHORT + ["--set", "mesh.cells=[80,8]"] + CHECKPOINT, signal.SIGTERM)
p = run([BINARY], "run", scene("default"), "--restart", out, *SHORT, "--set", "mesh.cells=[80,8]", "--set",
        "coupling.L=kdr", *CHECKPOINT)
check(p.returncode == 2 and p.stderr.strip().count("\n") == 0 and "another scene" in p.stderr,
      f"a restart with other --set values is refused: {p.stderr.strip()!r}")
empty = tempfile.mkdtemp()
p = run([BINARY], "run", scene("default"), "--restart", empty)
check(p.returncode == 2 and "no checkpoint" in p.stderr and p.stderr.strip().count("\n") == 0,
      f"a directory without a checkpoint is refused: {p.stderr.strip()!r}")
