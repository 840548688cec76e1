"""The Python prototype (python_prototype/) mirrors the C++ solver: on seven
cases (direct and iterative solvers), run side by side, every field agrees to 1e-8 relative at every output
time, and the coupling iterations of every step and the active contact sets
are identical (the `compare` command of the prototype)."""
import subprocess
import tempfile

from support import BINARY, MPI_ENV, ROOT, check, scene, summary

PROTOTYPE = ["/usr/bin/python3", "-m", "python_prototype"]
ENV = dict(MPI_ENV, PYTHONPATH=ROOT)


def keys(d, prefix=""):
    """The keys of a summary, nested ones as a.b, in order."""
    return [k for key, v in d.items()
            for k in [prefix + key] + (keys(v, prefix + key + ".") if isinstance(v, dict) else [])]


CASES = [
    ("terzaghi", scene("terzaghi"), []),
    ("default", scene("default"), []),
    ("default, multirate q = 4", scene("default"), ["--set", "coupling.scheme=multirate", "--set", "coupling.q=4"]),
    ("default, multirate-two-pass q = 4", scene("default"), ["--set", "coupling.scheme=multirate-two-pass",
                                                             "--set", "coupling.q=4"]),
    ("default, monolithic", scene("default"), ["--set", "coupling.scheme=monolithic"]),
    ("default, iterative solvers", scene("default"), ["--set", "solver.flow=iterative",
                                                      "--set", "solver.mechanics=iterative"]),
    ("default, monolithic iterative", scene("default"), ["--set", "coupling.scheme=monolithic",
                                                         "--set", "solver.monolithic=iterative",
                                                         "--set", "time.end=2"]),
]

for label, path, extra in CASES:
    cpp, py = tempfile.mkdtemp(prefix="biotcontact-cpp-"), tempfile.mkdtemp(prefix="biotcontact-py-")
    # Both at once (two cores): the runs are independent.
    runs = [subprocess.Popen(exe + ["run", path, "--out", out, *extra], stdout=subprocess.PIPE,
                             stderr=subprocess.PIPE, text=True, env=ENV)
            for exe, out in (([BINARY], cpp), (PROTOTYPE, py))]
    for p, name in zip(runs, ("C++", "prototype")):
        stdout, stderr = p.communicate(timeout=900)
        check(p.returncode == 0, f"{label}: the {name} run succeeds ({p.returncode}: {stderr.strip()[-300:]})")
    c = subprocess.run(PROTOTYPE + ["compare", cpp, py, "--tolerance", "1e-8"], capture_output=True, text=True,
                       env=ENV)
    print(c.stdout, end="")
    check(c.returncode == 0, f"{label}: fields within 1e-8, same coupling iterations and active sets")
    a, b = summary(cpp), summary(py)
    same = [k for k in ("steps", "coupling_iterations", "flow_solves", "mechanics_solves", "monolithic_solves",
                        "newton_iterations", "bound_violations", "resolved_ratios", "unresolved_ratios")
            if a[k] != b[k]]
    check(not same, f"{label}: same counts in summary.json (differing: {same})")
    check(keys(a) == keys(b), f"{label}: summary.json has the same keys in the same order "
          f"(C++ only: {sorted(set(keys(a)) - set(keys(b)))}, prototype only: {sorted(set(keys(b)) - set(keys(a)))})")
    print(f"   wall time: C++ {a['wall_time_s']:.1f} s, prototype {b['wall_time_s']:.1f} s (run side by side)")
