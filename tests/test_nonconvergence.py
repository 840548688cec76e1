"""A split that does not converge is an error with the iteration log, and
what was finished before it stays written."""
import os

from support import Fields, check, iterations, run, scene, summary

out, p = run(scene("default"), "--set", "coupling.max_iterations=3", expect=3)
line = p.stderr.strip().splitlines()
check(len(line) == 1 and "did not converge in 3 iterations" in line[0] and "iterations.csv" in line[0],
      f"one-line error naming the log: {p.stderr.strip()[:160]!r}")
rows = iterations(out)
check(len(rows) == 3 and [r["iteration"] for r in rows] == ["1", "2", "3"], "all three iterations logged")
s = summary(out)
check(s["converged"] is False and "failure" in s, "summary says converged = false, with the reason")
check(os.path.exists(os.path.join(out, "solution.xdmf")) and
      Fields(out).times("displacement") == [0.0], "the initial state is written")

# Steps converged before the failing one stay written: the load arrives at
# t = 1 (step 6), the steps before it converge at once, step 6 cannot.
out, p = run(scene("default"), "--set", "coupling.max_iterations=10",
             "--set", "boundary.top.traction=[0.0, '-1e3*(t>1)']", expect=3)
check("at t = 1.2 (step 6)" in p.stderr, f"the failure is in step 6: {p.stderr.strip()[:100]!r}")
s = summary(out)
times = Fields(out).times("displacement")
check(s["steps"] == 5 and len(times) == 6 and abs(times[-1] - 1.0) < 1e-12,
      f"the 5 finished steps are kept (output times {times})")
