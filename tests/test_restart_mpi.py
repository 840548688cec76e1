"""Restarts on any partition (issue 21): a checkpoint names each value by the
mesh's input numbering (a node's, a cell's, a facet's vertices'), so a run
checkpointed on 2 ranks goes on, on 2 ranks (the same partition) or on 1,
and a 1-rank checkpoint on 2, each ending with the uninterrupted 1-rank
run's fields (1e-8: the ranks sum in another order), active sets and
coupling iterations: the split with contact, the monolithic solve and (C++)
fault_reactivation's frictional fault; a 2-rank run killed by SIGKILL goes
on from its last periodic checkpoint on 2 ranks, and a C++ run continued on
2 ranks ends with the uninterrupted 2-rank run's fields to the bit (the
fluxes' signs included). A checkpoint of another mesh under the same scene
text (another size, or its nodes moved) is refused in one line on 1 and 2
ranks, no output touched, on both tracks."""
import dataclasses
import os
import shutil
import signal
import subprocess
import sys
import tempfile
import time

from support import BINARY, EVERY_RANK, MPI_ENV, PROTOTYPE, ROOT, check, mpirun, scene

sys.path.insert(0, ROOT)
from python_prototype.output.compare import compare  # noqa: E402

CHECKPOINT = ["--set", "output.checkpoint_every=3"]


TRACKS = {"C++": [BINARY], "prototype": PROTOTYPE}


def command(track, ranks, scene_file, *arguments):
    """Every rank works, also in the one-rank runs: a restart on another
    number of ranks has the same --set values."""
    cmd = [*TRACKS[track], "run", scene_file, *arguments, *EVERY_RANK]
    return mpirun(ranks) + cmd if ranks > 1 else cmd


def execute(track, ranks, scene_file, *arguments):
    return subprocess.run(command(track, ranks, scene_file, *arguments), capture_output=True, text=True,
                          env=MPI_ENV, cwd=ROOT, timeout=900)


def has_checkpoint(directory):
    folder = os.path.join(directory, "checkpoint")
    return os.path.isdir(folder) and any(name.startswith("state.") for name in os.listdir(folder))


def ranks_of(out):
    """The ranks of the run writing to `out` (their command lines name it),
    without mpirun."""
    found = subprocess.run(["pgrep", "-f", out], capture_output=True, text=True).stdout.split()
    pids = []
    for pid in map(int, found):
        try:
            with open(f"/proc/{pid}/cmdline", "rb") as f:
                program = os.path.basename(f.read().split(b"\0")[0].decode())
        except FileNotFoundError:
            continue
        if program not in ("mpirun", "mpiexec", "orterun"):
            pids.append(pid)
    return pids


def stopped_run(track, ranks, scene_file, options):
    """A run on `ranks` stopped by SIGTERM as soon as it prints its first
    line: the signal is recorded during the set-up (the handlers come first)
    and the run stops after its first step, however fast the machine or
    slow the forwarding of its output. Under mpirun the signal goes to every
    rank at once and not to mpirun, as SLURM's --signal sends it: mpirun
    answers a SIGTERM of its own by killing the ranks a second later
    (odls_base_sigkill_timeout), before a slow first step has ended
    (docs/user-guide.md, "Interruption")."""
    out = tempfile.mkdtemp(prefix="restart-mpi-")
    p = subprocess.Popen(command(track, ranks, scene_file, "--out", out, *options), stdout=subprocess.PIPE,
                         stderr=subprocess.PIPE, text=True, env=MPI_ENV, cwd=ROOT)
    p.stdout.readline()
    if ranks > 1:
        for pid in ranks_of(out):
            os.kill(pid, signal.SIGTERM)
    else:
        p.send_signal(signal.SIGTERM)
    _, err = p.communicate(timeout=600)
    check("interrupted" in err and has_checkpoint(out),
          f"{track}: {ranks} rank(s) stopped by SIGTERM with a checkpoint ({err.strip()[-200:]!r})")
    return out


def stamps(directory):
    """Each output file's modification time (.lock records who holds it)."""
    return {name: os.stat(os.path.join(directory, name)).st_mtime_ns for name in os.listdir(directory)
            if name != ".lock"}


def killed_run(track, ranks, scene_file, options):
    """A run on `ranks` killed (SIGKILL to mpirun and every rank at once, as
    when a node fails) as soon as its first periodic checkpoint is in place:
    it dies a few steps later, with that checkpoint its last. The ranks are
    found by the output directory on their command lines (Open MPI starts
    them in sessions of their own)."""
    out = tempfile.mkdtemp(prefix="restart-mpi-killed-")
    p = subprocess.Popen(command(track, ranks, scene_file, "--out", out, *options), stdout=subprocess.DEVNULL,
                         stderr=subprocess.DEVNULL, env=MPI_ENV, cwd=ROOT)
    while not has_checkpoint(out) and p.poll() is None:
        time.sleep(0.01)
    subprocess.run(["pkill", "-KILL", "-f", out])
    p.wait(timeout=600)
    while subprocess.run(["pgrep", "-f", out], capture_output=True).returncode == 0:
        time.sleep(0.1)
    check(p.returncode == -signal.SIGKILL and has_checkpoint(out),
          f"{track}: {ranks} rank(s) killed by SIGKILL after its first periodic checkpoint ({p.returncode})")
    return out


@dataclasses.dataclass
class Case:
    """A scene and its --set values, named."""
    label: str
    scene_file: str
    options: list


def continues_the_run(track, case, whole, ranks, stop=stopped_run):
    """Checkpointed on ranks[0], restarted on ranks[1]: the uninterrupted
    1-rank run (whole[1]) to 1e-8, and on an unchanged rank count its own
    uninterrupted run (whole[ranks[0]], where given) to the bit: one
    partition per mesh and rank count (PT-Scotch on one thread)."""
    stopped_on, restarted_on = ranks
    checkpointed = stop(track, stopped_on, case.scene_file, case.options)
    p = execute(track, restarted_on, case.scene_file, "--restart", checkpointed, *case.options)
    label = f"{track}, {case.label}"
    check(p.returncode == 0 and "restarted from the checkpoint at step" in p.stdout,
          f"{label}: checkpointed on {stopped_on}, restarted on {restarted_on} rank(s), runs to the end "
          f"({p.stderr.strip()[-200:]!r})")
    lines = []
    agreed = compare(whole[1], checkpointed, tolerance=1e-8, out=lines.append) == 0
    check(agreed, f"{label}, {stopped_on} -> {restarted_on} rank(s): the uninterrupted run's fields to 1e-8, "
          f"active sets and coupling iterations:\n  " + "\n  ".join(lines[1:]))
    if stopped_on == restarted_on and stopped_on in whole:
        lines = []
        agreed = compare(whole[stopped_on], checkpointed, tolerance=0.0, out=lines.append) == 0
        check(agreed, f"{label}, {stopped_on} -> {restarted_on} rank(s): the uninterrupted {stopped_on}-rank "
              f"run to the bit:\n  " + "\n  ".join(lines[1:]))


# The default scene, refined and shortened (the signal stops a run after its
# first step however fast it is: stopped_run); fault_reactivation's
# frictional fault, whose slip, stick and slip states and seismic moments
# the checkpoint carries across the partitions.
SMALL = ["--set", "mesh.cells=[80,8]", "--set", "time.end=2.4"]
CASES = [Case("split with contact", scene("default"), CHECKPOINT + SMALL),
         Case("monolithic", scene("default"), CHECKPOINT + ["--set", "coupling.scheme=monolithic"] + SMALL),
         Case("frictional fault", scene("fault_reactivation"), CHECKPOINT + ["--set", "time.end=864000"])]
# The fault on the C++ track alone: the prototype's partitioned checkpoints
# are the default scene's.
for track, rank_changes, cases in [("C++", [(2, 2), (2, 1), (1, 2)], CASES),
                                   ("prototype", [(2, 1), (1, 2)], CASES[:2])]:
    for case in cases:
        whole = {}
        for ranks in sorted({1} | {a for a, b in rank_changes if a == b}):
            whole[ranks] = tempfile.mkdtemp(prefix="whole-")
            p = execute(track, ranks, case.scene_file, "--out", whole[ranks], *case.options)
            check(p.returncode == 0, f"{track}, {case.label}: the uninterrupted run on {ranks} rank(s) "
                  f"({p.stderr.strip()[-200:]!r})")
        for change in rank_changes:
            continues_the_run(track, case, whole, change)
        if case.label == "split with contact":
            continues_the_run(track, Case(case.label + ", killed", case.scene_file, case.options), whole, (2, 2),
                              stop=killed_run)

# Another mesh under the same scene text: the gmsh file changed in between,
# to another size, or to the same size with its nodes moved.
folder = tempfile.mkdtemp(prefix="restart-mesh-")
scene_file = os.path.join(folder, "hertz.toml")
geometry_file = os.path.join(folder, "hertz.geo")
shutil.copy(scene("hertz"), scene_file)
shutil.copy(os.path.join(ROOT, "meshes", "hertz.geo"), geometry_file)
with open(geometry_file) as f:
    geometry = f.read()
options = ["--set", "time.dt=0.1", "--set", "output.checkpoint_every=1"]
CHANGES = [("another size", geometry.replace("SizeMin = 0.004", "SizeMin = 0.005"), "cells"),
           ("moved nodes", geometry.replace("Plane Surface(1) = {1};", "Plane Surface(1) = {1};\n"
                                            "Translate {0.001, 0, 0} { Surface{1}; }"), "nodes moved")]
for track in TRACKS:
    with open(geometry_file, "w") as f:
        f.write(geometry)
    checkpointed = tempfile.mkdtemp(prefix="restart-mesh-out-")
    p = execute(track, 2, scene_file, "--out", checkpointed, *options)
    check(p.returncode == 0 and has_checkpoint(checkpointed),
          f"{track}: the Hertz scene on 2 ranks leaves its checkpoint ({p.stderr.strip()[-200:]!r})")
    before = stamps(checkpointed)
    for change, changed, reason in CHANGES:
        with open(geometry_file, "w") as f:
            f.write(changed)
        for ranks in (1, 2):
            p = execute(track, ranks, scene_file, "--restart", checkpointed, *options)
            # mpirun adds its own report of the exit code; ours is one line.
            ours = [line for line in p.stderr.splitlines() if line.startswith("biotcontact")]
            error = "\n".join(ours)
            check(p.returncode == 2 and len(ours) == 1 and "does not match this mesh" in error
                  and "PETSC ERROR" not in p.stderr and "Traceback" not in p.stderr and reason in error,
                  f"{track}: a checkpoint of a mesh with {change} is refused on {ranks} rank(s) in one line: "
                  f"{error!r}")
    check(before == stamps(checkpointed), f"{track}: the refused restarts touched no file of the run")
