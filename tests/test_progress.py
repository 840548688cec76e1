"""Progress a user can plan by (issue 20): every step line ends with the
wall time so far and an estimate of the time left ("[1.2 s, 3.4 s left]",
the last one "0.0 s left"), and within a step a line every
output.progress_interval seconds (10 by default) names the coupling
iteration and its increments, or the contact Newton step of a single solve,
so that a long run never looks hung. The interval is set to 1e-9 s here, so
that every iteration prints; with the default no short run prints any. Both
tracks print the same lines."""
import re
import subprocess
import sys
import tempfile

from support import MPI_ENV, ROOT, check, run, scene

STEP = re.compile(r"^step +(\d+)/(\d+) .*\[([\d.]+) s, ([\d.]+) s left\]$")
EVERY = ["--set", "time.end=1.2", "--set", "output.progress_interval=1e-9"]


PROTOTYPE = ["/usr/bin/python3", "-m", "python_prototype", "run"]


def lines(*extra, track="cpp"):
    if track == "cpp":
        _, p = run(scene("default"), *extra)
    else:
        p = subprocess.run(PROTOTYPE + [scene("default"), "--out", tempfile.mkdtemp(), *extra], capture_output=True,
                           text=True, env=dict(MPI_ENV, PYTHONPATH=ROOT), timeout=600)
        if p.returncode != 0:
            sys.exit(f"FAIL: prototype run {' '.join(extra)}: exit {p.returncode}\n{p.stderr[-2000:]}")
    return p.stdout.splitlines()


def check_step_lines(out, label):
    steps = [STEP.match(line) for line in out if line.startswith("step")]
    check(steps and all(steps), f"{label}: every one of {len(steps)} step lines has the time so far and left")
    elapsed = [float(m.group(3)) for m in steps]
    check(elapsed == sorted(elapsed), f"{label}: the time so far never decreases ({elapsed})")
    last = steps[-1]
    check(last.group(1) == last.group(2) and float(last.group(4)) == 0.0,
          f"{label}: the last step has nothing left ({out[-2] if len(out) > 1 else out})")


def check_track(track):
    split = lines(*EVERY, track=track)
    check_step_lines(split, f"{track} split")
    iterations = [line for line in split if re.match(r"^  \.\.\. step \d+: coupling iteration \d+, increments dp ", line)]
    check(len(iterations) >= 8, f"{track} split: a line at every coupling iteration ({len(iterations)})")

    monolithic = lines(*EVERY, "--set", "coupling.scheme=monolithic", track=track)
    check_step_lines(monolithic, f"{track} monolithic")
    newton = [line for line in monolithic if re.match(r"^  \.\.\. step \d+: monolithic contact Newton step \d+", line)]
    check(len(newton) >= 4, f"{track} monolithic: a line at every contact Newton step ({len(newton)})")

    quiet = lines("--set", "time.end=1.2", track=track)
    check_step_lines(quiet, f"{track} default interval")
    check(not [line for line in quiet if line.startswith("  ...")],
          f"{track} default interval: a short run prints no lines within its steps")


for track in ("cpp", "prototype"):
    check_track(track)
