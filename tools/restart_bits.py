#!/usr/bin/python3
"""Is a restart exact to the bit on a scene? Runs it whole, runs it again
killed by SIGKILL once iterations.csv has ROWS lines (after a periodic
checkpoint, output.checkpoint_every = 3), continues it with --restart, and
prints the largest relative difference of every field of solution.xdmf and
of every dataset of fault.h5 against the whole run (0 means to the bit).

    /usr/bin/python3 tools/restart_bits.py SCENE:ROWS [SCENE:ROWS ...] [--binary build/biotcontact]

e.g. `fault_reactivation:200 injection_fault3d:100` (scenes/NAME.toml);
the user guide's "Restart" quotes its results.
"""
import argparse
import os
import shutil
import signal
import subprocess
import sys
import tempfile
import time

import h5py
import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, ROOT)
from python_prototype.output.compare import compare  # noqa: E402

CHECKPOINT = ["--set", "output.checkpoint_every=3"]


def rows(out):
    try:
        with open(os.path.join(out, "iterations.csv")) as f:
            return sum(1 for _ in f)
    except OSError:
        return 0


def run(binary, scene, out, kill_at=None):
    """Runs the scene into `out`; with kill_at, kills it by SIGKILL once
    iterations.csv has that many lines and a checkpoint exists."""
    shutil.rmtree(out, ignore_errors=True)
    p = subprocess.Popen([binary, "run", scene, "--out", out] + CHECKPOINT, stdout=subprocess.DEVNULL,
                         stderr=subprocess.DEVNULL)
    if kill_at:
        while p.poll() is None and (rows(out) < kill_at or not os.path.isdir(os.path.join(out, "checkpoint"))):
            time.sleep(0.005)
        killed = p.poll() is None
        p.send_signal(signal.SIGKILL)
        p.wait()
        return killed
    p.wait()
    return False


def fault_difference(a, b):
    """The largest relative difference over fault.h5's datasets (None without one)."""
    path_a, path_b = os.path.join(a, "fault.h5"), os.path.join(b, "fault.h5")
    if not os.path.exists(path_a):
        return None
    worst = [0.0]
    with h5py.File(path_a) as fa, h5py.File(path_b) as fb:
        def visit(key, obj):
            if isinstance(obj, h5py.Dataset) and obj.dtype.kind == "f" and key in fb:
                x, y = np.asarray(obj), np.asarray(fb[key])
                if x.shape == y.shape and x.size:
                    worst[0] = max(worst[0], np.abs(x - y).max() / max(np.abs(x).max(), 1e-300))
        fa.visititems(visit)
    return worst[0]


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("cases", nargs="+", help="SCENE:ROWS, SCENE a name in scenes/")
    p.add_argument("--binary", default=os.path.join(ROOT, "build", "biotcontact"))
    args = p.parse_args()
    work = tempfile.mkdtemp(prefix="restart-bits-")
    for case in args.cases:
        name, kill_at = case.split(":")
        scene = os.path.join(ROOT, "scenes", f"{name}.toml")
        whole, cut = os.path.join(work, f"{name}-whole"), os.path.join(work, f"{name}-cut")
        run(args.binary, scene, whole)
        killed = run(args.binary, scene, cut, int(kill_at))
        subprocess.run([args.binary, "run", scene, "--restart", cut] + CHECKPOINT, stdout=subprocess.DEVNULL,
                       stderr=subprocess.DEVNULL, check=True)
        lines = []
        compare(whole, cut, tolerance=0.0, out=lines.append)
        worst = max((float(line.split("difference")[1].split()[0]) for line in lines if "relative difference" in line),
                    default=None)
        print(f"{name}: {'killed mid-run' if killed else 'finished before the kill'}; solution.xdmf worst {worst}, "
              f"fault.h5 worst {fault_difference(whole, cut)}", flush=True)
    shutil.rmtree(work, ignore_errors=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
