"""The regression cases: every shipped scene (shortened where it is long) and
the coupling schemes and solver paths on the default scene. record.py stores
what each case computes on both tracks; test_regression.py checks that a
later build computes the same."""
import csv
import ctypes
import json
import os
import subprocess
import sys

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
sys.path.insert(0, ROOT)
from python_prototype.output.time_series import Fields  # noqa: E402

DEFAULT = "default"
CASES = {
    "block3d": ("block3d", []),
    "block3d_box": ("block3d_box", []),
    "darcy": ("darcy", []),
    "default": (DEFAULT, ["--set", "time.end=4.0"]),
    "elastic_contact": ("elastic_contact", []),
    "fracture": ("fracture", ["--set", "time.end=1296000.0"]),
    "fracture3d": ("fracture3d", []),  # to its end: at 10 days the touching nodes' pressures are round-off
    "hertz": ("hertz", []),
    "hertz_poroelastic": ("hertz_poroelastic", ["--set", "time.end=0.02"]),
    "mandel": ("mandel", ["--set", "time.end=100.0"]),
    "terzaghi": ("terzaghi", ["--set", "time.end=0.2"]),
    "terzaghi_contact": ("terzaghi_contact", ["--set", "time.end=0.2"]),
    "multirate": (DEFAULT, ["--set", "time.end=3.2", "--set", "coupling.scheme=multirate", "--set", "coupling.q=4"]),
    "two_pass": (DEFAULT, ["--set", "time.end=3.2", "--set", "coupling.scheme=multirate-two-pass",
                           "--set", "coupling.q=4"]),
    "anderson": (DEFAULT, ["--set", "time.end=4.0", "--set", "coupling.acceleration=anderson"]),
    "monolithic": (DEFAULT, ["--set", "time.end=4.0", "--set", "coupling.scheme=monolithic"]),
    "iterative": (DEFAULT, ["--set", "time.end=2.0", "--set", "solver.flow=iterative",
                            "--set", "solver.mechanics=iterative"]),
    "monolithic_iterative": (DEFAULT, ["--set", "time.end=2.0", "--set", "coupling.scheme=monolithic",
                                       "--set", "solver.monolithic=iterative"]),
}
COUNTS = ("steps", "coupling_iterations", "flow_solves", "mechanics_solves", "monolithic_solves",
          "newton_iterations", "bound_violations", "resolved_ratios", "unresolved_ratios", "retries")
ENV = dict(os.environ, PYTHONPATH=ROOT, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")


def blas_kernel():
    """The BLAS this process (and a solver started from it) computes with:
    OpenBLAS and the kernel it chose for this CPU (OPENBLAS_CORETYPE may
    choose it), or the library behind libblas.so.3. Round-off, and so the
    last digits of a field, depend on it."""
    try:
        blas = ctypes.CDLL("libblas.so.3")
    except OSError:
        return "none"
    if hasattr(blas, "openblas_get_corename"):
        blas.openblas_get_corename.restype = ctypes.c_char_p
        return "OpenBLAS " + blas.openblas_get_corename().decode()
    with open("/proc/self/maps") as f:
        paths = {line.split()[-1] for line in f if "libblas" in line}
    return ", ".join(sorted(paths)) or "unknown"


def command(track, binary):
    return [binary] if track == "cpp" else ["/usr/bin/python3", "-m", "python_prototype"]


def run(case, track, binary, out):
    """Runs one case on one track into out; returns the process."""
    scene, extra = CASES[case]
    cmd = command(track, binary) + ["run", os.path.join(ROOT, "scenes", scene + ".toml"), "--out", out, *extra]
    return subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=ENV)


def outcome(out):
    """What a run computed: the split's coupling iterations of every step, the
    summary's counts, the active contact set at every output time and every
    field at the final time (sorted by coordinates, so that two builds
    compare whatever their numbering)."""
    result = {}
    with open(os.path.join(out, "iterations.csv")) as f:
        last = {}
        for row in csv.DictReader(f):
            if row["gamma"]:  # the split's coupling iterations (a single solve's rows have no gamma)
                last[int(row["step"])] = int(row["iteration"])
    result["iterations"] = np.array([last[k] for k in sorted(last)], dtype=np.int64)
    with open(os.path.join(out, "summary.json")) as f:
        summary = json.load(f)
    result["counts"] = np.array([summary.get(k, -1) for k in COUNTS], dtype=np.float64)
    fields = Fields(out)
    for name in sorted(fields.series):
        times = fields.times(name)
        result["final_" + name] = fields.sorted(name, times[-1])[0]
        if name == "contact_active":
            result["active_sets"] = np.array([fields.sorted(name, t)[0][:, 0] > 0.5 for t in times])
    return result
