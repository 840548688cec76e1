"""Helpers shared by the ctest scripts: run the solver, read its output.

Every temporary directory a test makes (tempfile's, in this process) lies
in one scratch directory removed when the test ends, passed or failed: a
suite run leaves nothing behind (the runs of test_theis alone take 454 MB).
BIOTCONTACT_KEEP_TEST_RUNS=1 keeps it, to look at a failure's runs."""
import atexit
import csv
import dataclasses
import json
import os
import re
import shutil
import signal
import subprocess
import sys
import tempfile

import h5py
import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
tempfile.tempdir = tempfile.mkdtemp(prefix=f"biotcontact-{os.path.splitext(os.path.basename(sys.argv[0]))[0]}-")
if os.environ.get("BIOTCONTACT_KEEP_TEST_RUNS") != "1":
    atexit.register(shutil.rmtree, tempfile.tempdir, ignore_errors=True)
sys.path.insert(0, ROOT)
from python_prototype.output.time_series import Fields, read_time_series  # noqa: E402,F401
# Open MPI's start-up, in every process the tests start: a one-rank run
# (a singleton) would start a helper daemon and every run would try UCX
# before settling on shared memory, 0.33 of the 0.35 s MPI_Init takes on
# this machine (docs/verification.md, "Runs and what they printed").
# Neither changes a result; a value set outside the tests is kept.
os.environ.setdefault("OMPI_MCA_ess_singleton_isolated", "1")
os.environ.setdefault("OMPI_MCA_pml", "ob1")
BINARY = os.environ.get("BIOTCONTACT", os.path.join(ROOT, "build", "biotcontact"))
PHAN_GEO = os.path.join(ROOT, "meshes", "phan2d.geo")  # the crack of Phan et al. (test_phan.py)
# Phan et al.'s plate (test_phan.py): E = 25 GPa, nu = 0.25, plane strain, the
# crack of PHAN_GEO, a uniaxial compression of 100 MPa through the top, one
# step; a scene adds its [fault.crack].
PHAN_E, PHAN_NU, PHAN_SIGMA = 25.0e9, 0.25, 1.0e8
PHAN_PLATE = f"""[mesh]
type = "gmsh"
file = "{PHAN_GEO}"
dimension = 2
[mechanics]
E = {PHAN_E}
nu = {PHAN_NU}
[time]
end = 1.0
dt = 1.0
[boundary.bottom]
displacement = {{ y = 0.0 }}
[boundary.left]
displacement = {{ x = 0.0 }}
[boundary.top]
traction = [0.0, {-PHAN_SIGMA}]
"""
PROTOTYPE = ["/usr/bin/python3", "-m", "python_prototype"]  # run with cwd=ROOT
TRACKS = {"C++": [BINARY], "prototype": PROTOTYPE}
MPI_ENV = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1",
               OMPI_MCA_rmaps_base_oversubscribe="1")


# A test on several ranks is about the distributed run: every rank works
# however few cells the scene has (cpp/domain/working_ranks.h).
EVERY_RANK = ["--set", "solver.cells_per_rank=0"]


def mpirun(ranks):
    """The command that starts `ranks` ranks: mpirun once no other test's
    mpirun runs (tests/mpirun_alone.py)."""
    return ["/usr/bin/python3", "-S", os.path.join(ROOT, "tests", "mpirun_alone.py"), "-n", str(ranks)]


def scene(name):
    return os.path.join(ROOT, "scenes", name + ".toml")


def run(scene_file, *extra, ranks=1, expect=0, out=None):
    """Runs the solver; returns (output directory, completed process)."""
    out = out or tempfile.mkdtemp(prefix="biotcontact-test-")
    cmd = [BINARY, "run", scene_file, "--out", out, *extra]
    if ranks > 1:
        cmd = mpirun(ranks) + cmd + EVERY_RANK
    p = subprocess.run(cmd, capture_output=True, text=True, env=MPI_ENV, timeout=900)
    if expect is not None and p.returncode != expect:
        sys.exit(f"FAIL: {' '.join(cmd)} exited {p.returncode}, expected {expect}\n"
                 f"{p.stdout[-3000:]}\n{p.stderr[-3000:]}")
    return out, p


def written(text, name="scene.toml"):
    """A scene file with `text` in a new temporary folder."""
    path = os.path.join(tempfile.mkdtemp(prefix="scene-"), name)
    with open(path, "w") as f:
        f.write(text)
    return path


def compressed(p):
    """The sides of a rectangle on rollers (left, bottom), pressed by p
    (Pa) on the right and the top."""
    return (f"[boundary.left]\ndisplacement = {{ x = 0.0 }}\n[boundary.bottom]\ndisplacement = {{ y = 0.0 }}\n"
            f"[boundary.right]\ntraction = [{-p!r}, 0.0]\n[boundary.top]\ntraction = [0.0, {-p!r}]\n")


def gas_in_rigid_rock(c_f):
    """[flow] and [coupling] of a gas (compressibility c_f, 1/Pa) in conduit
    faults through impermeable rock that it does not load (alpha = 0)."""
    return (f"[flow]\nM = 1.0e10\nc_f = {c_f!r}\nmu_f = 1.0e-5\npermeability = 1.0e-25\ninitial_pressure = 0.0\n"
            "[coupling]\nalpha = 0.0\ntolerance = 1e-10\nmax_iterations = 50\n")


def gmsh_scene(geo, text, dimension=2, end=1.0):
    """A scene of linear elasticity (E = 1e10 Pa, nu = 0.25), steps of 1 s
    to `end`, on the gmsh .geo text `geo` (written beside it as mesh.geo),
    then `text` (its boundaries and faults), in a new temporary folder."""
    path = written(f'[mesh]\ntype = "gmsh"\nfile = "mesh.geo"\ndimension = {dimension}\n'
                   f"[mechanics]\nE = 1.0e10\nnu = 0.25\n[time]\nend = {end!r}\ndt = 1.0\n" + text)
    with open(os.path.join(os.path.dirname(path), "mesh.geo"), "w") as f:
        f.write(geo)
    return path


CRACK_GEO = os.path.join(ROOT, "meshes", "sneddon2d.geo")
CRACK_TEXT = f"""[mesh]
type = "gmsh"
file = "{CRACK_GEO}"
dimension = 2
[mechanics]
E = 1.0e10
nu = 0.25
[time]
end = 1.0
dt = 1.0
[fault.crack]
pressure = "1.0e6"
normal = [-0.5, 0.8660254037844386]
[boundary.left]
displacement = {{ x = 0.0, y = 0.0 }}
"""
CROSSING_GEO = """SetFactory("Built-in");
Point(1) = {-2, -2, 0}; Point(2) = {2, -2, 0}; Point(3) = {2, 2, 0}; Point(4) = {-2, 2, 0};
Point(5) = {-1, 0, 0}; Point(6) = {0, 0, 0}; Point(7) = {1, 0, 0}; Point(8) = {0, -1, 0}; Point(9) = {0, 1, 0};
Line(1) = {1, 2}; Line(2) = {2, 3}; Line(3) = {3, 4}; Line(4) = {4, 1};
Line(5) = {5, 6}; Line(6) = {6, 7}; Line(7) = {8, 6}; Line(8) = {6, 9};
Curve Loop(1) = {1, 2, 3, 4}; Plane Surface(1) = {1};
Curve{5, 6, 7, 8} In Surface{1};
Physical Curve("left") = {4}; Physical Curve("crack") = {5, 6}; Physical Curve("other") = {7, 8};
Physical Surface("rock") = {1};
Mesh.CharacteristicLengthMax = 0.25;
"""


# Two planes across a 2 x 2 x 1 box, x = 1 (PLANE_A) and y = 1 (PLANE_B),
# crossing along x = y = 1 (OpenCASCADE's fragments; each side a group;
# test_fault_network.py, test_fault_junctions.py).
CROSS_GEO = """SetFactory("OpenCASCADE");
Mesh.CharacteristicLengthMax = 0.25;
Box(1) = {0, 0, 0, 2, 2, 1};
Rectangle(10) = {1, 0, 0, 1, 2}; Rotate {{0, 1, 0}, {1, 0, 0}, -Pi/2} { Surface{10}; }
Rectangle(11) = {0, 1, 0, 2, 1}; Rotate {{1, 0, 0}, {0, 1, 0}, Pi/2} { Surface{11}; }
BooleanFragments{ Volume{1}; Delete; }{ Surface{10, 11}; Delete; }
e = 1e-6;
Physical Volume("rock") = Volume{:};
Physical Surface("left") = Surface In BoundingBox{-e, -e, -e, e, 2 + e, 1 + e};
Physical Surface("right") = Surface In BoundingBox{2 - e, -e, -e, 2 + e, 2 + e, 1 + e};
Physical Surface("front") = Surface In BoundingBox{-e, -e, -e, 2 + e, e, 1 + e};
Physical Surface("back") = Surface In BoundingBox{-e, 2 - e, -e, 2 + e, 2 + e, 1 + e};
Physical Surface("bottom") = Surface In BoundingBox{-e, -e, -e, 2 + e, 2 + e, e};
Physical Surface("top") = Surface In BoundingBox{-e, -e, 1 - e, 2 + e, 2 + e, 1 + e};
"""
PLANE_A = 'Physical Surface("a") = Surface In BoundingBox{1 - e, -e, -e, 1 + e, 2 + e, 1 + e};\n'
PLANE_B = 'Physical Surface("b") = Surface In BoundingBox{-e, 1 - e, -e, 2 + e, 1 + e, 1 + e};\n'


def crack_scenes():
    """The bad-input catalogues' faulted scenes (test_bad_scenes.py and its
    prototype twin), paths of new files: a crack in a gmsh mesh
    (meshes/sneddon2d.geo), mechanics only, as a .geo and as that .geo
    meshed once into a .msh, and the crack with tip cells of 0.0025 m,
    where gmsh makes one of zero area. The crack is meshed 8 times coarser
    near it (its sizes' `scale`): 0.3 s a launch instead of 1 s, and from
    the .msh, which most of the dozens of bad inputs given to it use, no
    meshing at each launch."""
    coarse = written(f'scale = 8;\nInclude "{CRACK_GEO}";\n', "coarse.geo")
    crack = written(CRACK_TEXT.replace(CRACK_GEO, coarse))
    meshed = coarse.replace(".geo", ".msh")
    subprocess.run(["gmsh", "-2", "-format", "msh41", coarse, "-o", meshed], check=True, capture_output=True)
    crack_msh = written(CRACK_TEXT.replace(CRACK_GEO, meshed))
    degenerate = written(CRACK_TEXT.replace(CRACK_GEO, "degenerate.geo"))
    with open(CRACK_GEO) as f:
        geo = f.read().replace("Field[4].SizeMin = 0.004 * scale;", "Field[4].SizeMin = 0.0025;")
    with open(os.path.join(os.path.dirname(degenerate), "degenerate.geo"), "w") as f:
        f.write(geo)
    return crack, crack_msh, degenerate


PINNED_GEO = """SetFactory("Built-in");
Point(1) = {-2, -2, 0}; Point(2) = {2, -2, 0}; Point(3) = {2, 2, 0}; Point(4) = {-2, 2, 0};
Point(5) = {-2, 0, 0}; Point(6) = {1, 0.5, 0}; Point(7) = {1, -0.5, 0};
Line(1) = {1, 2}; Line(2) = {2, 3}; Line(3) = {3, 4}; Line(4) = {4, 5}; Line(5) = {5, 1};
Line(6) = {5, 6}; Line(7) = {5, 7};
Curve Loop(1) = {1, 2, 3, 4, 5}; Plane Surface(1) = {1};
Curve{6, 7} In Surface{1};
Physical Curve("left") = {4, 5}; Physical Curve("crack") = {6}; Physical Curve("other") = {7};
Physical Surface("rock") = {1};
Mesh.CharacteristicLengthMax = 0.25;
"""


def fault_group_scenes():
    """The catalogues' faults drawn wrong in gmsh, in crossing.geo's square:
    a crack whose curve is not embedded in the surface, one curve given to
    two faults' physical groups, and two faults that meet on the clamped
    side."""
    loose = written(CRACK_TEXT.replace(CRACK_GEO, "loose.geo"))
    with open(os.path.join(os.path.dirname(loose), "loose.geo"), "w") as f:
        f.write(CROSSING_GEO.replace("Curve{5, 6, 7, 8} In Surface{1};\n", ""))
    shared = written(CRACK_TEXT.replace(CRACK_GEO, "shared.geo") + "[fault.other]\nnormal = [0.0, 1.0]\n")
    with open(os.path.join(os.path.dirname(shared), "shared.geo"), "w") as f:
        f.write(CROSSING_GEO.replace('Physical Curve("other") = {7, 8};', 'Physical Curve("other") = {5};'))
    pinned = written(CRACK_TEXT.replace(CRACK_GEO, "pinned.geo") + "[fault.other]\nnormal = [0.0, 1.0]\n")
    with open(os.path.join(os.path.dirname(pinned), "pinned.geo"), "w") as f:
        f.write(PINNED_GEO)
    return loose, shared, pinned


FOUNDATION_FAULT_GEO = """SetFactory("Built-in");
h = 0.05;
Point(1) = {0, 0, 0, h}; Point(2) = {0.5, 0, 0, h}; Point(3) = {1, 0, 0, h};
Point(4) = {1, 1, 0, h}; Point(5) = {0, 1, 0, h}; Point(6) = {0.5, 0.6, 0, h};
Line(1) = {1, 2}; Line(2) = {2, 3}; Line(3) = {3, 4}; Line(4) = {4, 5}; Line(5) = {5, 1}; Line(6) = {2, 6};
Curve Loop(1) = {1, 2, 3, 4, 5}; Plane Surface(1) = {1};
Curve{6} In Surface{1};
Physical Curve("bottom") = {1, 2}; Physical Curve("right") = {3}; Physical Curve("top") = {4};
Physical Curve("left") = {5}; Physical Curve("fault") = {6}; Physical Surface("rock") = {1};
"""


def foundation_fault_scene():
    """The catalogues' fault that reaches a contact boundary: a unit square
    on a rigid foundation (bottom), a vertical fault from (0.5, 0) to a tip
    at (0.5, 0.6), mechanics only."""
    path = written("""[mesh]
type = "gmsh"
file = "fault.geo"
dimension = 2
[mechanics]
E = 1.0e9
nu = 0.3
[time]
end = 1.0
dt = 0.5
[boundary.left]
displacement = { x = 0.0 }
[boundary.top]
traction = [2.0e5, "-1e6*t"]
[boundary.bottom]
contact = { gap = 0.0, normal = [0.0, -1.0] }
[fault.fault]
normal = [1.0, 0.0]
friction = 0.6
""")
    with open(os.path.join(os.path.dirname(path), "fault.geo"), "w") as f:
        f.write(FOUNDATION_FAULT_GEO)
    return path


def flow_crack_scene():
    """The catalogues' crack (meshes/sneddon2d.geo) in a flow scene (rigid
    walls), the fault transparent: where conduit faults are refused."""
    return written(f"""[mesh]
type = "gmsh"
file = "{CRACK_GEO}"
dimension = 2
[flow]
mu_f = 1.0e-3
permeability = 1.0e-12
[time]
end = 1.0
dt = 1.0
[fault.crack]
normal = [-0.5, 0.8660254037844386]
[boundary.left]
pressure = 1.0e6
""")


class PrototypeWorker:
    """The prototype's command line run in one long-lived process
    (tests/prototype_worker.py), for tests that run it on dozens of bad
    inputs; a command line with PETSc options gets a process of its own."""

    def __init__(self):
        self.process = None

    def run(self, argv, cwd=ROOT):
        """(exit status, standard error) of `python3 -m python_prototype ARGV`."""
        if any(a.startswith("-") and not a.startswith("--") for a in argv):
            p = subprocess.run(PROTOTYPE + argv, capture_output=True, text=True, env=MPI_ENV, cwd=cwd, timeout=300)
            return p.returncode, p.stderr
        if self.process is None or self.process.poll() is not None:
            self.process = subprocess.Popen(["/usr/bin/python3", os.path.join(ROOT, "tests", "prototype_worker.py")],
                                            stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True, env=MPI_ENV)
        self.process.stdin.write(json.dumps({"argv": argv, "cwd": cwd}) + "\n")
        self.process.stdin.flush()
        answer = self.process.stdout.readline()
        if not answer:  # the worker died (an abort or a crash of the prototype): say so as the status
            return -1, f"the prototype's process ended on {argv} with status {self.process.wait()}"
        answer = json.loads(answer)
        return answer["status"], answer["stderr"]


def run_track(track, scene_file, *sets, expect=0, ranks=1, options=()):
    """Runs a scene on one track ("C++" or "prototype") with --set values
    and PETSc `options`, on `ranks` MPI ranks, checking its exit status;
    returns (output directory, completed process)."""
    out = tempfile.mkdtemp(prefix="run-")
    p = subprocess.run([*(mpirun(ranks) if ranks > 1 else []), *TRACKS[track], "run", scene_file, "--out", out,
                        *[a for s in sets for a in ("--set", s)], *(EVERY_RANK if ranks > 1 else []), *options],
                       capture_output=True, text=True, env=MPI_ENV, cwd=ROOT, timeout=900)
    check(p.returncode == expect, f"{track}: {os.path.basename(scene_file)} {' '.join(sets)} exits {expect} "
          f"({p.stderr.strip()[-300:]!r})")
    return out, p


def restarted(track, scene_file, out, *sets, expect=0, ranks=1):
    """Continues the run in `out` from its checkpoint with --set values on
    `ranks` MPI ranks, checking its exit status; returns the completed
    process. Unlike run_track it adds no EVERY_RANK: the --set values are
    in the checkpoint's fingerprint, so a run restarted on several ranks
    names solver.cells_per_rank = 0 among its own `sets` from the start."""
    p = subprocess.run([*(mpirun(ranks) if ranks > 1 else []), *TRACKS[track], "run", scene_file, "--restart", out,
                        *[a for s in sets for a in ("--set", s)]],
                       capture_output=True, text=True, env=MPI_ENV, cwd=ROOT, timeout=900)
    check(p.returncode == expect, f"{track}: {os.path.basename(scene_file)} --restart {' '.join(sets)} exits {expect} "
          f"({p.stderr.strip()[-300:]!r})")
    return p


def poroelastic_column(fixed):
    """The mechanics of the mass-balance tests' 2D columns (alpha = 0.8,
    coupling tolerance 1e-12): rollers on the sides, boundary `fixed` held
    vertically."""
    return f"""[mechanics]
G = 1.0e9
lambda = 1.0e9
[coupling]
alpha = 0.8
tolerance = 1e-12
scheme = "fixed-stress"
[boundary.left]
displacement = {{ x = 0.0 }}
[boundary.right]
displacement = {{ x = 0.0 }}
[boundary.{fixed}]
displacement = {{ y = 0.0 }}
"""


def summary(out):
    with open(os.path.join(out, "summary.json")) as f:
        return json.load(f)


def iterations(out):
    with open(os.path.join(out, "iterations.csv")) as f:
        return list(csv.DictReader(f))


def check(condition, message):
    if not condition:
        sys.exit("FAIL: " + message)
    print("ok: " + message)


@dataclasses.dataclass
class Foundation:
    """Where check_signorini looks: the contact nodes at coordinate 0 along
    `axis`, u.nu_F = sign u[axis]; or, for a foundation of another normal,
    `side` (the contact nodes' mask) and `normal` (their unit normals,
    n x d), functions of the nodes' coordinates."""
    axis: int = 1
    sign: float = -1.0
    side: object = None
    normal: object = None


def check_signorini(out, gap, foundation=Foundation(), label="", pressure_scale="time"):
    """u.nu_F <= g_a, contact pressure >= 0 and complementarity at every
    contact node of the `foundation` and every output time; returns the
    active counts per time. `gap` is a number, or a function of the nodes'
    coordinates (n x 3). Contact pressures are judged against the largest
    at that time, or with pressure_scale="run" the largest of the run (where
    a node of zero gap touches without load, the pressures of that time are
    all round-off)."""
    fields = Fields(out)
    axis, sign, normal = foundation.axis, foundation.sign, foundation.normal
    side = foundation.side(fields.nodes) if foundation.side else np.isclose(fields.nodes[:, axis], 0.0)
    gap = gap(fields.nodes[side]) if callable(gap) else gap
    run_scale = max(fields.at("contact_pressure", t)[side, 0].max() for t in fields.times("displacement"))
    counts = []
    for t in fields.times("displacement"):
        u = fields.at("displacement", t)[side]
        u_nu = np.sum(u[:, :normal(fields.nodes[side]).shape[1]] * normal(fields.nodes[side]), axis=1) \
            if normal else sign * u[:, axis]
        p_c = fields.at("contact_pressure", t)[side, 0]
        active = fields.at("contact_active", t)[side, 0]
        scale = max(np.max(gap), np.abs(fields.at("displacement", t)).max())
        p_scale = max(run_scale if pressure_scale == "run" else p_c.max(), 1e-300)
        check((u_nu - gap).max() <= 1e-10 * scale,
              f"{label}t={t:g}: no penetration (max u.nu - g = {(u_nu - gap).max():.2e})")
        if active.sum() > 0:
            check(p_c.min() >= -1e-8 * p_scale, f"{label}t={t:g}: contact pressure >= 0 (min {p_c.min():.2e}, max {p_scale:.2e})")
            comp = np.abs(p_c * (u_nu - gap)).max()
            check(comp <= 1e-8 * p_scale * scale, f"{label}t={t:g}: complementarity {comp:.2e}")
        counts.append(int(active.sum()))
    return counts


def max_difference(a, b, names, sort=False):
    """Largest difference over all output times of each field, relative to
    the field's largest value over the run."""
    fa, fb = Fields(a), Fields(b)
    result = {}
    for name in names:
        get_a = fa.sorted_values if sort else fa.at
        get_b = fb.sorted_values if sort else fb.at
        times = fa.times(name)
        check(times == fb.times(name), f"{name}: same output times")
        scale = max(max(np.abs(get_a(name, t)).max() for t in times), 1e-300)
        result[name] = max(np.abs(get_a(name, t) - get_b(name, t)).max() for t in times) / scale
    return result


def cell_measures(fields):
    """The area (2D) or volume (3D) of every cell of a run's mesh."""
    v = fields.nodes[fields.topology]
    edges = v[:, 1:] - v[:, :1]
    if v.shape[2] == 2:
        return 0.5 * np.abs(edges[:, 0, 0] * edges[:, 1, 1] - edges[:, 1, 0] * edges[:, 0, 1])
    return np.abs(np.linalg.det(edges)) / 6


def fluid_content(fields, t, storage, alpha=0.0):
    """The fluid content of each cell at time t, (S p + alpha div u) |T|,
    div u of the P1 displacement (2D only for alpha > 0): the mass balance
    tests of flux boundaries and wells sum it."""
    content = storage * fields.at("pressure", t)[:, 0] * cell_measures(fields)
    if np.any(np.asarray(alpha) > 0):
        x, cells = fields.nodes[:, :2], fields.topology
        u = fields.series["displacement"][min(fields.series["displacement"], key=lambda s: abs(s - t))][1][:, :2]
        centroid = x[cells].mean(axis=1)
        # The integral of div u over a triangle is the flux of u through its edges.
        for i, j in ((0, 1), (1, 2), (2, 0)):
            edge = x[cells[:, j]] - x[cells[:, i]]
            normal = np.stack([edge[:, 1], -edge[:, 0]], axis=1)
            normal *= np.sign(np.sum(normal * (x[cells[:, i]] - centroid), axis=1))[:, None]
            content += alpha * np.sum(0.5 * (u[cells[:, i]] + u[cells[:, j]]) * normal, axis=1)
    return content


def check_contact_scene_agrees(scene_file, sets, active_sets, runs, *settings):
    """What the test of a shipped contact scene asserts beyond its own
    physics: 2 ranks reach the same contact sets at every time (`sets`, of
    the 1-rank C++ run) and the same fields (1e-8); the monolithic solve the
    same contact sets, and the split at coupling tolerance 1e-12 its fields
    (1e-8); the prototype's run (`runs["prototype"]`) the C++ one to 1e-10.
    `active_sets(out)` lists a run's contact flags per output time;
    `settings` are the --set values of every run."""
    two, _ = run_track("C++", scene_file, *settings, ranks=2)
    check(all(np.array_equal(a, b) for a, b in zip(sets, active_sets(two))),
          "2 ranks: the same contact set at every time")
    worst = max_difference(runs["C++"], two, ["pressure", "displacement", "contact_pressure"])
    check(max(worst.values()) < 1e-8, f"2 ranks: the same fields ({', '.join(f'{k} {v:.1e}' for k, v in worst.items())})")
    monolithic, _ = run_track("C++", scene_file, *settings, "coupling.scheme=monolithic")
    check(all(np.array_equal(a, b) for a, b in zip(sets, active_sets(monolithic))),
          "the monolithic solve: the same contact set at every time")
    tight, _ = run_track("C++", scene_file, *settings, "coupling.tolerance=1e-12")
    worst = max_difference(tight, monolithic, ["pressure", "displacement"])
    check(max(worst.values()) < 1e-8, f"the split at coupling tolerance 1e-12 gives the monolithic fields "
          f"({', '.join(f'{k} {v:.1e}' for k, v in worst.items())})")
    c = subprocess.run(PROTOTYPE + ["compare", runs["C++"], runs["prototype"], "--tolerance", "1e-10"],
                       capture_output=True, text=True, cwd=ROOT)
    check(c.returncode == 0 and len(iterations(runs["C++"])) == len(iterations(runs["prototype"])),
          f"the prototype gives the C++ run to 1e-10 {c.stdout[-300:]}")


def windows(out, dt):
    """(q, active contact nodes at its end) of each accepted window, from
    iterations.csv (a window computed again logs its rows before the
    accepted ones; the last rows of a step are the accepted window's; step 0
    is the initial equilibrium, no window)."""
    last = {}
    for row in iterations(out):
        if int(row["step"]) > 0:
            last[int(row["step"])] = row
    t, result = 0.0, []
    for k in sorted(last):
        end = float(last[k]["time"])
        result.append((round((end - t) / dt), int(last[k]["active_nodes"])))
        t = end
    return result


def set_changes(out, dt, history):
    """The windows of q > 1 whose contact set (the contact_active field,
    node by node) at their end differs from the one at their start."""
    run = Fields(out)
    written = run.times("contact_active")
    ends = [min(written, key=lambda s: abs(s - t)) for t in [0.0, *np.cumsum([q for q, _ in history]) * dt]]
    check(len(set(ends)) == len(ends), "the contact set is written at every window's end")
    sets = [run.at("contact_active", t) for t in ends]
    return [k for k, (q, _) in enumerate(history) if q > 1 and not np.array_equal(sets[k], sets[k + 1])]


def fault_pairs(fields, normal):
    """The node pairs of a split fault in a run's output, found from the mesh
    alone (two nodes at one point; the + node's cells lie on the side
    `normal` points into): arrays (plus, minus) of node indices. A check
    independent of the solver's own pairing."""
    x = fields.nodes
    order = np.lexsort(np.round(x, 9).T[::-1])
    same = np.all(np.isclose(x[order[1:]], x[order[:-1]], rtol=0, atol=1e-9), axis=1)
    first, second = order[:-1][same], order[1:][same]
    side = np.zeros(len(x))
    for cell in fields.topology:
        offset = (x[cell].mean(axis=0) - x[cell]) @ np.asarray(normal)[:x.shape[1]]
        side[cell] += np.sign(offset)
    swap = side[first] < side[second]
    return np.where(swap, second, first), np.where(swap, first, second)


def unsplit_difference(with_fault, without, names):
    """The largest difference of each field between a run on a split mesh
    and the run on the same mesh without its faults, relative to each
    field's largest value: nodes matched by their point (a pair's two nodes
    both to the one node there), cells by index (the split keeps the cells
    and their order)."""
    a, b = Fields(with_fault), Fields(without)
    index = {tuple(np.round(x, 9)): i for i, x in enumerate(b.nodes)}
    matched = np.array([index[tuple(np.round(x, 9))] for x in a.nodes])
    worst = {}
    for name in names:
        scale = max(np.abs(b.at(name, t)).max() for t in b.times(name))
        nodal = len(a.at(name, a.times(name)[-1])) == len(a.nodes)
        worst[name] = max(np.abs(a.at(name, t) - (b.at(name, t)[matched] if nodal else b.at(name, t))).max()
                          for t in b.times(name)) / scale
    return worst


def fault_fields(out, names=("slip", "traction", "tangential_traction", "state")):
    """fault.xdmf and .h5 of a run: its node coordinates, its output times
    and, per time, the named fields."""
    with open(os.path.join(out, "fault.xdmf")) as f:
        times = [float(t) for t in re.findall(r'<Time Value="([^"]+)"', f.read())]
    with h5py.File(os.path.join(out, "fault.h5")) as f:
        series = [{name: f[f"{name}/{i}"][:] for name in names} for i in range(len(times))]
        return f["Mesh/geometry"][:], times, series


def killed(track, scene_file, steps, *sets, options=()):
    """A run with --set `sets` and PETSc `options`, killed (SIGKILL) once
    `steps` are written; its output directory."""
    out = tempfile.mkdtemp(prefix="killed-")
    p = subprocess.Popen(TRACKS[track] + ["run", scene_file, "--out", out, *[a for s in sets for a in ("--set", s)],
                                          *options],
                         stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=MPI_ENV, cwd=ROOT)
    printed = 0
    for line in p.stdout:
        printed += re.match(r"step +\d+/", line) is not None
        if printed == steps:
            p.send_signal(signal.SIGKILL)
            break
    p.communicate(timeout=300)
    return out


def killed_and_restarted(track, scene_file, steps, *extra):
    """A run with a checkpoint every 4 steps (and --set `extra`), killed
    once `steps` are written, then continued with --restart; its output
    directory and the step it restarted from."""
    out = killed(track, scene_file, steps, "output.checkpoint_every=4", *extra)
    p = restarted(track, scene_file, out, "output.checkpoint_every=4", *extra)
    step = re.search(r"restarted from the checkpoint at step (\d+)", p.stdout)
    check(step is not None, f"{track}: killed after step {steps} and restarted "
          f"from step {step.group(1) if step else '?'} ({p.stderr.strip()[-200:]!r})")
    return out, int(step.group(1))


def fault_centroids(out):
    """The centroids of fault.xdmf's cells (its cell data's order)."""
    with h5py.File(os.path.join(out, "fault.h5")) as f:
        return f["Mesh/geometry"][:][f["Mesh/topology"][:]].mean(axis=1)


# A crack of half-length 1 m at 30 degrees inside the square [-2, 2]^2 (an
# unstructured gmsh mesh with the sides "left", "right", "bottom", "top"):
# the small faulted scenes of test_transparent_fault.py and
# test_friction_coupled.py.
INCLINED_CRACK_GEO = """SetFactory("Built-in");
Point(1) = {-2, -2, 0}; Point(2) = {2, -2, 0}; Point(3) = {2, 2, 0}; Point(4) = {-2, 2, 0};
Point(5) = {-0.8660254037844386, -0.5, 0}; Point(6) = {0.8660254037844386, 0.5, 0};
Line(1) = {1, 2}; Line(2) = {2, 3}; Line(3) = {3, 4}; Line(4) = {4, 1}; Line(5) = {5, 6};
Curve Loop(1) = {1, 2, 3, 4}; Plane Surface(1) = {1};
Curve{5} In Surface{1};
Physical Curve("bottom") = {1}; Physical Curve("right") = {2}; Physical Curve("top") = {3};
Physical Curve("left") = {4}; Physical Curve("crack") = {5}; Physical Surface("rock") = {1};
Mesh.CharacteristicLengthMax = 0.2;
"""


# A fault across a 10 m x 2 m rock from its left side to its right side
# (cells of h = 0.25): the channel of the conduit fault's tests,
# meshes/channel2d.geo.
with open(os.path.join(ROOT, "meshes", "channel2d.geo")) as _channel:
    CHANNEL_GEO = _channel.read()


# The 3D channel of the conduit fault's tests: meshes/fault_box.geo.
with open(os.path.join(ROOT, "meshes", "fault_box.geo")) as _box:
    BOX_GEO = _box.read()
