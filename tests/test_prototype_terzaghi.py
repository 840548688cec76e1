"""The Python prototype alone passes the Terzaghi closed-form checks
(docs/verification.md, "Terzaghi"), errors computed as cpp/simulation.cpp does (P2
interpolants of the closed form)."""
import subprocess
import tempfile

from support import MPI_ENV, ROOT, check, scene, summary

out = tempfile.mkdtemp(prefix="biotcontact-py-")
p = subprocess.run(["/usr/bin/python3", "-m", "python_prototype", "run", scene("terzaghi"), "--out", out],
                   capture_output=True, text=True, env=dict(MPI_ENV, PYTHONPATH=ROOT), timeout=900)
check(p.returncode == 0, f"the prototype runs the Terzaghi scene ({p.stderr.strip()[-300:]})")
s = summary(out)
e = s["errors"]
check(s["converged"], "the split converged in every step")
check(e["pressure_rel_l2"] <= 0.02, f"pressure relative L2 error {e['pressure_rel_l2']:.3e} <= 2%")
check(e["settlement_rel"] <= 0.01, f"settlement error {e['settlement_rel']:.3e} <= 1%")
check(e["displacement_rel_l2"] <= 0.01, f"displacement relative L2 error {e['displacement_rel_l2']:.3e} <= 1%")
check(s["max_contraction_ratio"] <= s["gamma"] and s["bound_violations"] == 0,
      f"Theorem 1: max ratio {s['max_contraction_ratio']:.3f} <= gamma {s['gamma']:.3f}")
