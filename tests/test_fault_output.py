"""fault.xdmf (issue 37), on the C++ solver and the prototype, with
scenes/fault_depletion.toml (a vertical fault, its + side the right block):
meshio reads one grid per output time on the fault's + face (its pairs'
+ nodes and its two tips: one node more than segments, a single curve);
at the last time the slip is the jump of the displacement in
solution.xdmf at each pair found from the output mesh alone
(support.fault_pairs), to 1e-12; the opening is 0 where the traction is
positive; summary.json's max_slip is the largest |slip| there. The two
tracks write the same fault.xdmf text and fault.h5 datasets (1e-10). A run
killed after a periodic checkpoint and continued with --restart ends with
the uninterrupted run's fault.xdmf (the same text, values to 1e-12), the
times it wrote after the checkpoint written again."""
import os
import re
import signal
import subprocess
import tempfile

import h5py
import meshio
import numpy as np
from support import MPI_ENV, ROOT, TRACKS, Fields, check, fault_pairs, run_track, scene, summary

SCENE = scene("fault_depletion")


def fault_series(out):
    """(times, points, cells, per time its point data) of a run's fault.xdmf."""
    with meshio.xdmf.TimeSeriesReader(os.path.join(out, "fault.xdmf")) as reader:
        points, cells = reader.read_points_cells()
        data = [reader.read_data(k) for k in range(reader.num_steps)]
    return [t for t, _, _ in data], points, cells, [d for _, d, _ in data]


def check_run(track, out):
    """What one run's fault.xdmf says, against its solution.xdmf and summary."""
    times, points, cells, data = fault_series(out)
    fields = Fields(out)
    written = fields.times("displacement")
    plus, minus = fault_pairs(fields, [1.0, 0.0])
    check(times == written and [c.type for c in cells] == ["line"] and len(points) == len(plus) + 2
          and len(cells[0].data) == len(points) - 1, f"{track}: fault.xdmf has a grid at each of the "
          f"{len(written)} output times, {len(points)} nodes ({len(plus)} pairs and 2 tips) and "
          f"{len(cells[0].data)} segments")
    # The fault's node at each pair's place (the + node's coordinates).
    at = np.argmin(np.linalg.norm(points[None, :, :2] - fields.nodes[plus][:, None, :2], axis=2), axis=1)
    check(np.abs(points[at, :2] - fields.nodes[plus]).max() <= 1e-9,
          f"{track}: each of the {len(plus)} pairs of solution.xdmf is a node of fault.xdmf")
    last, u = data[-1], fields.at("displacement", written[-1])
    slip, jump = last["slip"][at, 1], u[plus, 1] - u[minus, 1]
    error = np.abs(slip - jump).max() / np.abs(jump).max()
    check(error <= 1e-12, f"{track}: the slip's y component is the jump of the displacement at every pair "
          f"(to {error:.1e}; largest {np.abs(jump).max():.4f} m)")
    largest = np.linalg.norm(last["slip"], axis=1).max()
    pressed = last["traction"][:, 0] > 0
    opening = np.abs(last["opening"][pressed, 0]).max(initial=0.0)
    check(pressed.sum() > 0 and opening <= 1e-12 * largest,
          f"{track}: the opening is 0 where the traction is positive ({pressed.sum()} nodes, largest {opening:.1e} m)")
    faults = summary(out)["contact"]["faults"]
    check(abs(faults["fault"]["max_slip"] - largest) <= 1e-12 * largest,
          f"{track}: summary.json's max_slip {faults['fault']['max_slip']:.6f} m is the largest |slip| of fault.xdmf")


def datasets(path):
    with h5py.File(path) as f:
        found = {}
        f.visititems(lambda name, d: found.update({name: d[()]}) if isinstance(d, h5py.Dataset) else None)
    return found


def same_datasets(a, b):
    """The largest difference of two fault.h5 files' datasets, each relative
    to its largest value (inf when they hold other datasets or shapes)."""
    da, db = datasets(os.path.join(a, "fault.h5")), datasets(os.path.join(b, "fault.h5"))
    if da.keys() != db.keys() or any(da[k].shape != db[k].shape for k in da):
        return np.inf, len(da)
    worst = max(np.abs(da[k] - db[k]).max(initial=0.0) / max(np.abs(da[k]).max(initial=0.0), 1e-300) for k in da)
    return worst, len(da)


def xml(out):
    with open(os.path.join(out, "fault.xdmf")) as f:
        return f.read()


runs = {}
for track in TRACKS:
    runs[track], _ = run_track(track, SCENE)
    check_run(track, runs[track])
worst, count = same_datasets(runs["C++"], runs["prototype"])
check(worst <= 1e-10, f"prototype = C++: the {count} datasets of fault.h5 to {worst:.1e} (limit 1e-10)")
check(xml(runs["C++"]) == xml(runs["prototype"]), "prototype = C++: the same fault.xdmf text")

# Restart: 16 steps, a checkpoint every 3; killed once step 5 is written, the
# run has written fault.xdmf past its checkpoint (step 3).
SETS = ["--set", "time.dt=0.25", "--set", "output.checkpoint_every=3"]
for track, exe in TRACKS.items():
    whole, _ = run_track(track, SCENE, *SETS[1::2])
    out = tempfile.mkdtemp(prefix="restart-")
    p = subprocess.Popen(exe + ["run", SCENE, "--out", out] + SETS, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                         text=True, env=MPI_ENV, cwd=ROOT)
    printed = 0
    for line in p.stdout:
        printed += re.match(r"step +\d+/", line) is not None
        if printed == 5:
            p.send_signal(signal.SIGKILL)
            break
    p.communicate(timeout=300)
    before = fault_series(out)[0]
    p = subprocess.run(exe + ["run", SCENE, "--restart", out] + SETS, capture_output=True, text=True,
                       env=MPI_ENV, cwd=ROOT, timeout=900)
    restarted = re.search(r"restarted from the checkpoint at step \d+, t = (\S+)", p.stdout)
    check(p.returncode == 0 and restarted is not None, f"{track}: the killed run restarts and runs to the end "
          f"({p.stderr.strip()[-200:]!r})")
    t_checkpoint = float(restarted.group(1))
    check(max(before) > t_checkpoint, f"{track}: the killed run's fault.xdmf went past its checkpoint "
          f"(t = {max(before):g} > {t_checkpoint:g})")
    worst, count = same_datasets(whole, out)
    check(xml(whole) == xml(out) and worst <= 1e-12,
          f"{track}: after the restart fault.xdmf is the uninterrupted run's ({len(fault_series(out)[0])} times, the "
          f"same text; the {count} datasets to {worst:.1e})")
