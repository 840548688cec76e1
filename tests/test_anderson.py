"""Anderson acceleration of the fixed-stress split (issue 13,
coupling.acceleration = "anderson"): on the default scene, whose contact set
changes during the run, the accelerated split converges to the monolithic
solution (1e-8 relative, with the split's tolerance at 1e-12) in fewer
coupling iterations than the plain split, with the same active sets; the
summary says so; the Python prototype takes the same iterations and gives
the same fields; multirate q = 4 converges too."""
import subprocess

from support import MPI_ENV, ROOT, check, check_signorini, max_difference, run, scene, summary

ANDERSON = ["--set", "coupling.acceleration=anderson"]
TIGHT = ["--set", "coupling.tolerance=1e-12", "--set", "coupling.max_iterations=400"]

mono, _ = run(scene("default"), "--set", "coupling.scheme=monolithic")
plain, _ = run(scene("default"), *TIGHT)
accelerated, _ = run(scene("default"), *TIGHT, *ANDERSON)
s_plain, s_acc = summary(plain), summary(accelerated)
check(s_acc["acceleration"] == "anderson, depth 8" and s_plain["acceleration"] == "auto, depth 8"
      and s_plain["accelerated_windows"] == 0,
      f"the summary says whether the split was accelerated ({s_acc['acceleration']!r})")
check(s_acc["coupling_iterations"] < s_plain["coupling_iterations"],
      f"Anderson: {s_acc['coupling_iterations']} coupling iterations against {s_plain['coupling_iterations']} "
      "(tolerance 1e-12)")
for name, d in max_difference(accelerated, mono, ("displacement", "pressure", "flux")).items():
    check(d <= 1e-8, f"accelerated split vs monolithic: {name} {d:.1e} <= 1e-8")
counts = check_signorini(accelerated, 0.0012, label="Anderson ")
check(counts == check_signorini(mono, 0.0012, label="monolithic "), f"same active sets as monolithic {counts}")

# At the default tolerance (1e-8), the iterations the studies compare.
default_plain, _ = run(scene("default"), "--set", "output.xdmf=false")
default_acc, _ = run(scene("default"), *ANDERSON)
n_plain, n_acc = (summary(o)["coupling_iterations"] for o in (default_plain, default_acc))
check(n_acc < n_plain, f"tolerance 1e-8: {n_acc} coupling iterations against {n_plain}")

# The prototype mirrors it: same iterations, same fields.
out_py = default_acc + "-py"
p = subprocess.run(["/usr/bin/python3", "-m", "python_prototype", "run", scene("default"), "--out", out_py, *ANDERSON],
                   capture_output=True, text=True, cwd=ROOT, env=dict(MPI_ENV, PYTHONPATH=ROOT))
check(p.returncode == 0, f"the prototype runs with Anderson acceleration ({p.stderr.strip()[-200:]!r})")
c = subprocess.run(["/usr/bin/python3", "-m", "python_prototype", "compare", default_acc, out_py],
                   capture_output=True, text=True, cwd=ROOT, env=dict(MPI_ENV, PYTHONPATH=ROOT))
check(c.returncode == 0, "prototype and C++ agree with Anderson acceleration: " + c.stdout.strip().splitlines()[-1])

# Multirate q = 4: the accelerated window (p^1..p^4, u) converges.
multirate, _ = run(scene("default"), "--set", "coupling.scheme=multirate", "--set", "coupling.q=4", *ANDERSON)
check(summary(multirate)["converged"], f"multirate q = 4 with Anderson converges "
      f"({summary(multirate)['coupling_iterations']} coupling iterations)")
