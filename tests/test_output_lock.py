"""One run per output directory (issue 21): a run holds a lock on DIR/.lock
while it writes there. A second run into the directory, started while the
first is running, exits 2 with one line naming the directory and the
running process, before it creates or truncates any file; the first
completes with fields, iterations.csv and summary equal to the same run
alone. The prototype takes the same lock (a C++ run blocks a prototype run
and back). After a SIGKILL the kernel has dropped the lock: a new run into
the directory starts normally. --restart takes the lock too."""
import filecmp
import json
import os
import signal
import subprocess
import sys
import tempfile

import numpy as np
from support import BINARY, MPI_ENV, ROOT, Fields, check, scene

SCENE = scene("default")
RUN = ["--set", "mesh.cells=[160,16]", "--set", "time.end=4.8"]
TRACKS = {"cpp": [BINARY], "prototype": [sys.executable, "-m", "python_prototype"]}
ENV = dict(MPI_ENV, PYTHONPATH=ROOT)
TIMINGS = ("timings", "wall_time_s")  # the summary's wall-clock times


def start(track, out, *extra):
    return subprocess.Popen(TRACKS[track] + ["run", SCENE, "--out", out, *RUN, *extra], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True, env=ENV)


def wait_for_step(p):
    """Reads the run's output until its first step line."""
    for line in p.stdout:
        if line.startswith("step"):
            return
    check(False, "the first run printed a step")


def listing(out):
    return {f: (os.stat(os.path.join(out, f)).st_size, os.stat(os.path.join(out, f)).st_mtime_ns)
            for f in sorted(os.listdir(out))}


def without_timings(summary):
    return {k: v for k, v in summary.items() if k not in TIMINGS}


def same_results(out, alone, label):
    check(filecmp.cmp(os.path.join(out, "iterations.csv"), os.path.join(alone, "iterations.csv"), shallow=False),
          f"{label}: iterations.csv equal to the run alone")
    s = [without_timings(json.load(open(os.path.join(d, "summary.json")))) for d in (out, alone)]
    check(s[0] == s[1], f"{label}: summary equal to the run alone (timings aside)")
    a, b = Fields(out), Fields(alone)
    for name in ("displacement", "pressure", "contact_pressure"):
        t = a.times(name)
        check(t == b.times(name) and all(np.array_equal(a.at(name, x), b.at(name, x)) for x in t),
              f"{label}: {name} at all {len(t)} output times equal to the run alone")


alone = tempfile.mkdtemp(prefix="lock-alone-")
subprocess.run([BINARY, "run", SCENE, "--out", alone, *RUN], check=True, capture_output=True, env=ENV)

for first, second in (("cpp", "cpp"), ("cpp", "prototype"), ("prototype", "cpp")):
    label = f"{first} running, {second} started"
    out = tempfile.mkdtemp(prefix="lock-")
    a = start(first, out)
    wait_for_step(a)
    before = listing(out)
    b = start(second, out)
    _, error = b.communicate(timeout=300)
    check(b.returncode == 2, f"{label}: the second run exits 2 (got {b.returncode})")
    lines = error.strip().splitlines()
    check(len(lines) == 1 and out in lines[0] and "in use by another run" in lines[0]
          and f"process {a.pid} " in lines[0], f"{label}: one line naming the directory and the process: {lines}")
    after = listing(out)
    touched = [f for f in before if f in after and after[f] != before[f] and f not in ("iterations.csv",
                                                                                      "solution.h5", "solution.xdmf")]
    check(set(after) == set(before) and not touched,
          f"{label}: the second run created and truncated nothing ({sorted(set(after) ^ set(before))}, {touched})")
    a.communicate(timeout=600)
    check(a.returncode == 0, f"{label}: the first run completes")
    if first == "cpp":
        same_results(out, alone, label)

for track in TRACKS:
    label = f"{track}: after a SIGKILL"
    out = tempfile.mkdtemp(prefix="lock-killed-")
    a = start(track, out)
    wait_for_step(a)
    a.send_signal(signal.SIGKILL)
    a.communicate(timeout=60)
    p = subprocess.run(TRACKS[track] + ["run", SCENE, "--out", out, *RUN], capture_output=True, text=True, env=ENV)
    check(p.returncode == 0, f"{label}: a new run into its directory starts and completes ({p.stderr.strip()[-200:]})")

out = tempfile.mkdtemp(prefix="lock-restart-")
a = start("cpp", out, "--set", "output.checkpoint_every=1")
wait_for_step(a)
p = subprocess.run([BINARY, "run", SCENE, "--restart", out, *RUN, "--set", "output.checkpoint_every=1"],
                   capture_output=True, text=True, env=ENV)
check(p.returncode == 2 and "in use by another run" in p.stderr, f"--restart into a running run's directory: exit 2 "
      f"with the line ({p.returncode}: {p.stderr.strip()})")
a.communicate(timeout=300)
