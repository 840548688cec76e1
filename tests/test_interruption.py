"""Nothing finished is lost when a run is stopped (issue 12). SIGTERM and
SIGINT mid-run: the step being computed is finished and written, the run
exits with 128 + the signal, summary.json says "interrupted" with the last
completed time, and h5py and meshio read every completed step. SIGKILL: no
summary, but every output time listed in solution.xdmf is readable with h5py
and meshio (each time is flushed as it is written). SIGINT twice (Ctrl-C
again) during a long step: the run stops at once, as SIGKILL would, on both
tracks."""
import json
import os
import signal
import subprocess
import tempfile
import time
import xml.etree.ElementTree as ET

import h5py
import meshio
import numpy as np
from support import BINARY, PROTOTYPE, ROOT, check, scene

STEPS_BEFORE_SIGNAL = 5


def interrupted_run(number):
    """Runs the default scene at [160,16] and sends `number` once a few steps
    are done; returns (exit status, output directory, steps printed)."""
    out = tempfile.mkdtemp(prefix=f"interrupt-{number}-")
    p = subprocess.Popen([BINARY, "run", scene("default"), "--set", "mesh.cells=[160,16]", "--out", out],
                         stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    printed = 0
    for line in p.stdout:
        if line.startswith("step"):
            printed += 1
            if printed == STEPS_BEFORE_SIGNAL:
                p.send_signal(number)
                break
    rest, error = p.communicate(timeout=300)
    printed += sum(1 for line in rest.splitlines() if line.startswith("step"))
    return p.returncode, out, printed, error


def interrupted_twice(command, label):
    """Runs the default scene at [480,48] (steps of 1-2 s), sends SIGINT
    0.2 s after the first step is done (after its check for a signal) and
    again 0.2 s later, within the second step: the run ends by the signal,
    without finishing that step. (With 1 s and 0.5 s the second step ended
    between the two signals on a fast host, 2026-12-01.)"""
    out = tempfile.mkdtemp(prefix="interrupt-twice-")
    p = subprocess.Popen(command + ["run", scene("default"), "--set", "mesh.cells=[480,48]", "--out", out],
                         stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, cwd=ROOT)
    for line in p.stdout:
        if line.startswith("step"):
            time.sleep(0.2)
            p.send_signal(signal.SIGINT)
            time.sleep(0.2)
            p.send_signal(signal.SIGINT)
            break
    rest, _ = p.communicate(timeout=300)
    check(p.returncode == -signal.SIGINT, f"{label}: SIGINT twice: ended by the signal ({p.returncode})")
    check(not os.path.exists(os.path.join(out, "summary.json")) and "step    2" not in rest,
          f"{label}: SIGINT twice: step 2 not finished, no summary.json")
    times = readable_steps(out, f"{label}, SIGINT twice")
    check(len(times) == 2, f"{label}: SIGINT twice: the initial state and step 1 readable ({len(times)} times)")


def readable_steps(out, label):
    """Every grid of solution.xdmf: its datasets through h5py and meshio."""
    xdmf = os.path.join(out, "solution.xdmf")
    grids = [g for g in ET.parse(xdmf).iter("Grid") if g.get("GridType") == "Uniform"]
    with h5py.File(os.path.join(out, "solution.h5"), "r") as h5:
        for g in grids:
            for a in g.findall("Attribute"):
                values = h5[a.find("DataItem").text.split(":")[1]][:]
                if not np.all(np.isfinite(values)):
                    check(False, f"{label}: {a.get('Name')} at t = {g.find('Time').get('Value')} is not finite")
    with meshio.xdmf.TimeSeriesReader(xdmf) as reader:
        reader.read_points_cells()
        for k in range(reader.num_steps):
            reader.read_data(k)
        steps = reader.num_steps
    check(steps == len(grids), f"{label}: h5py and meshio read all {len(grids)} output times")
    return [float(g.find("Time").get("Value")) for g in grids]


for number in (signal.SIGTERM, signal.SIGINT):
    label = signal.Signals(number).name
    status, out, printed, error = interrupted_run(number)
    check(status == 128 + number, f"{label}: exit status {status} == {128 + number}")
    check(error.strip().count("\n") == 0 and "interrupted" in error, f"{label}: one line says so: {error.strip()!r}")
    with open(os.path.join(out, "summary.json")) as f:
        s = json.load(f)
    times = readable_steps(out, label)
    check(s["status"] == "interrupted" and s["steps"] == printed and s["steps"] < 48,
          f"{label}: summary.json says interrupted after {s['steps']} of 48 steps ({printed} printed)")
    check(times[-1] == s["last_completed_time"] and len(times) == s["steps"] + 1,
          f"{label}: the output ends at the last completed time {s['last_completed_time']} "
          f"({len(times)} times: the initial state and every step)")

status, out, printed, _ = interrupted_run(signal.SIGKILL)
check(status == -signal.SIGKILL, f"SIGKILL: killed ({status})")
check(not os.path.exists(os.path.join(out, "summary.json")), "SIGKILL: no summary.json (nothing could write it)")
times = readable_steps(out, "SIGKILL")
check(len(times) >= printed + 1, f"SIGKILL: {len(times)} output times readable for {printed} steps printed")

interrupted_twice([BINARY], "C++")
interrupted_twice(PROTOTYPE, "prototype")
