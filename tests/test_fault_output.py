"""fault.xdmf (issue 37), both tracks, on scenes/fault_depletion.toml: one
grid per output time on the fault's + face; the slip is solution.xdmf's
displacement jump at each pair (1e-12), the opening 0 where the traction
is positive, summary.json's max_slip the largest |slip|. Frictionless
states on this run and with the upper fault pressurised open: 0 exactly
where the opening exceeds the closed tolerance, 2 at the other pairs, 1 at
the tips, tangential traction round-off (1e-10), `slipping` the measure of
state 2 (= `closed`), `stuck` 0. The two tracks write the same text and
datasets (1e-10); a restart after a periodic checkpoint ends with the
uninterrupted fault.xdmf (1e-12), its later times written again (from a
damaged fault.xdmf: exit 4, one line); with two cracks the cell field
`fault` numbers them in the summary's (alphabetical) order."""
import os
import re
import shutil
import subprocess
import tempfile

import h5py
import meshio
import numpy as np
from support import MPI_ENV, ROOT, TRACKS, Fields, check, fault_pairs, gmsh_scene, killed, run_track, scene, summary

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
    at, plus, minus = pair_nodes(fields, points)
    check(times == written and [c.type for c in cells] == ["line"] and len(points) == len(plus) + 2
          and len(cells[0].data) == len(points) - 1, f"{track}: fault.xdmf has a grid at each of the "
          f"{len(written)} output times, {len(points)} nodes ({len(plus)} pairs and 2 tips) and "
          f"{len(cells[0].data)} segments")
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


def pair_nodes(fields, points):
    """The node of fault.xdmf at each pair of solution.xdmf (the + node's
    coordinates), and the pairs (plus, minus) themselves."""
    plus, minus = fault_pairs(fields, [1.0, 0.0])
    at = np.argmin(np.linalg.norm(points[None, :, :2] - fields.nodes[plus][:, None, :2], axis=2), axis=1)
    return at, plus, minus


def lumped(points, cells):
    """Each node's lumped measure on the fault: half the lengths of its segments."""
    measure = np.zeros(len(points))
    for a, b in cells[0].data:
        half = np.linalg.norm(points[a] - points[b]) / 2
        measure[a] += half
        measure[b] += half
    return measure


def check_states(label, out):
    """The pairs' states of a frictionless run at every output time, its
    tangential traction and the summary's measures of the states."""
    times, points, cells, data = fault_series(out)
    fields = Fields(out)
    at, _, _ = pair_nodes(fields, points)
    tips = np.setdiff1d(np.arange(len(points)), at)
    opened, wrong, worst = 0, [], 0.0
    for t, d in zip(times, data):
        # The solver's closed test: a distance (the opening) within 1e-9 of
        # the displacement scale, the largest |u_i| (the gaps are 0).
        tolerance = 1e-9 * np.abs(fields.at("displacement", t)).max()
        state, opening = d["state"][:, 0], d["opening"][:, 0]
        expected = np.where(opening[at] > tolerance, 0.0, 2.0)
        opened = max(opened, int(np.sum(expected == 0)))
        if not (np.array_equal(state[at], expected) and np.all(state[tips] == 1.0)):
            wrong.append(t)
        scale = np.abs(d["traction"]).max()
        worst = max(worst, np.linalg.norm(d["tangential_traction"], axis=1).max() / scale if scale > 0 else 0.0)
        if scale == 0 and np.abs(d["tangential_traction"]).max() > 0:
            wrong.append(t)
    check(not wrong and len(tips) == 2, f"{label}: state is 0 exactly where the opening exceeds the closed "
          f"tolerance (up to {opened} of {len(at)} pairs), 2 at the other pairs, 1 at the {len(tips)} tips, at "
          f"all {len(times)} times (wrong at {wrong})")
    check(worst <= 1e-10, f"{label}: the tangential traction is round-off, {worst:.1e} of the largest traction "
          "(limit 1e-10)")
    fault = summary(out)["contact"]["faults"]["fault"]
    slipping = lumped(points, cells)[data[-1]["state"][:, 0] == 2.0].sum()
    check(fault["slipping"] == fault["closed"] and fault["stuck"] == 0
          and abs(fault["slipping"] - slipping) <= 1e-12 * slipping,
          f"{label}: summary.json's slipping {fault['slipping']:.6f} m is closed ({fault['closed']:.6f} m) and the "
          f"length of the nodes in state 2 ({slipping:.6f} m); stuck {fault['stuck']}")


def datasets(path):
    with h5py.File(path) as f:
        found = {}
        f.visititems(lambda name, d: found.update({name: d[()]}) if isinstance(d, h5py.Dataset) else None)
    return found


def same_datasets(a, b):
    """The largest difference of two fault.h5 files' datasets, each relative
    to its largest value, the tangential traction (round-off on a
    frictionless fault) to the traction's (inf when they hold other datasets
    or shapes)."""
    da, db = datasets(os.path.join(a, "fault.h5")), datasets(os.path.join(b, "fault.h5"))
    if da.keys() != db.keys() or any(da[k].shape != db[k].shape for k in da):
        return np.inf, len(da)

    def scale(k):
        largest = np.abs(da[k]).max(initial=0.0)
        if k.startswith("tangential_traction/"):
            largest = max(largest, np.abs(da["traction/" + k.split("/")[1]]).max(initial=0.0))
        return max(largest, 1e-300)
    worst = max(np.abs(da[k] - db[k]).max(initial=0.0) / scale(k) for k in da)
    return worst, len(da)


def xml(out):
    with open(os.path.join(out, "fault.xdmf")) as f:
        return f.read()


# Two cracks in a clamped square under compression: zeta at y = 0.3, alpha
# at y = 0.7.
TWO_CRACKS_GEO = """SetFactory("Built-in");
Point(1) = {0, 0, 0}; Point(2) = {1, 0, 0}; Point(3) = {1, 1, 0}; Point(4) = {0, 1, 0};
Point(5) = {0.2, 0.3, 0}; Point(6) = {0.6, 0.3, 0}; Point(7) = {0.4, 0.7, 0}; Point(8) = {0.8, 0.7, 0};
Line(1) = {1, 2}; Line(2) = {2, 3}; Line(3) = {3, 4}; Line(4) = {4, 1}; Line(5) = {5, 6}; Line(6) = {7, 8};
Curve Loop(1) = {1, 2, 3, 4}; Plane Surface(1) = {1};
Curve{5, 6} In Surface{1};
Physical Curve("bottom") = {1}; Physical Curve("top") = {3};
Physical Curve("zeta") = {5}; Physical Curve("alpha") = {6}; Physical Surface("rock") = {1};
Mesh.CharacteristicLengthMax = 0.05;
"""
TWO_CRACKS = """[boundary.bottom]
displacement = { x = 0.0, y = 0.0 }
[boundary.top]
displacement = { x = 0.0, y = -1.0e-4 }
[fault.zeta]
normal = [0.0, 1.0]
[fault.alpha]
normal = [0.0, 1.0]
"""


def check_fault_ids(track):
    """fault.xdmf's `fault` field of the two cracks: each cell's fault by
    its height, in the alphabetical order of the names."""
    out, _ = run_track(track, gmsh_scene(TWO_CRACKS_GEO, TWO_CRACKS))
    times, points, cells, data = fault_series(out)
    with meshio.xdmf.TimeSeriesReader(os.path.join(out, "fault.xdmf")) as reader:
        reader.read_points_cells()
        ids = [np.ravel(reader.read_data(k)[2]["fault"][0]) for k in range(len(times))]
    y = points[cells[0].data].mean(axis=1)[:, 1]
    expected = np.where(np.isclose(y, 0.7), 0.0, np.where(np.isclose(y, 0.3), 1.0, -1.0))
    check(all(np.array_equal(i, expected) for i in ids) and (expected == 0).sum() > 0 and (expected == 1).sum() > 0,
          f"{track}: two cracks: fault.xdmf's fault id is 0 on alpha's {(expected == 0).sum()} segments and 1 on "
          f"zeta's {(expected == 1).sum()} at every time")
    return out


ids = [check_fault_ids(track) for track in TRACKS]
check(xml(ids[0]) == xml(ids[1]), "two cracks: prototype = C++: the same fault.xdmf text")

runs = {}
for track in TRACKS:
    runs[track], _ = run_track(track, SCENE)
    check_run(track, runs[track])
    check_states(track, runs[track])
    opened, _ = run_track(track, SCENE, 'fault.fault.pressure="40e6 * t / 4 * (y > 400 ? 1 : 0)"')
    check_states(f"{track}, pressurised above y = 400 m", opened)
worst, count = same_datasets(runs["C++"], runs["prototype"])
check(worst <= 1e-10, f"prototype = C++: the {count} datasets of fault.h5 to {worst:.1e} (limit 1e-10)")
check(xml(runs["C++"]) == xml(runs["prototype"]), "prototype = C++: the same fault.xdmf text")

# Restart: 16 steps, a checkpoint every 3; killed once step 5 is written, the
# run has written fault.xdmf past its checkpoint (step 3).
SETS = ["--set", "time.dt=0.25", "--set", "output.checkpoint_every=3"]
for track, exe in TRACKS.items():
    whole, _ = run_track(track, SCENE, *SETS[1::2])
    out = killed(track, SCENE, 5, *SETS[1::2])
    before = fault_series(out)[0]
    damaged = tempfile.mkdtemp(prefix="damaged-")
    shutil.copytree(out, damaged, dirs_exist_ok=True)
    with open(os.path.join(damaged, "fault.xdmf"), "w") as f:
        f.write(xml(out).replace('<Time Value="', '<Time Value="x', 1))
    p = subprocess.run(exe + ["run", SCENE, "--restart", damaged] + SETS, capture_output=True, text=True,
                       env=MPI_ENV, cwd=ROOT, timeout=300)
    lines = p.stderr.strip().splitlines()
    check(p.returncode == 4 and len(lines) == 1 and "error: opening the output: cannot resume" in lines[0]
          and 'fault.xdmf: its time "x0" is no number' in lines[0],
          f"{track}: a restart from a damaged fault.xdmf: exit {p.returncode}, {lines}")
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
