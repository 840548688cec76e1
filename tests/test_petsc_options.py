"""PETSc options choose the solvers: an iterative flow solve (GMRES is the
default Krylov method once the preconditioner is no factorisation) gives the
same answer as the direct default, and options that make no solver are
refused in one line, without a PETSc trace."""
import subprocess
import tempfile

from support import BINARY, check, run, scene, summary

direct = summary(run(scene("terzaghi"))[0])
iterative = summary(run(scene("terzaghi"), "-flow_pc_type", "ilu", "-flow_ksp_rtol", "1e-12")[0])
check(iterative["linear_iterations"]["flow"] > iterative["flow_solves"], "the flow system was solved by GMRES + ILU")
check(abs(iterative["errors"]["pressure_rel_l2"] - direct["errors"]["pressure_rel_l2"]) <= 1e-6,
      "GMRES + ILU gives the direct solve's error against the closed form")
p = subprocess.run([BINARY, "run", scene("terzaghi"), "--out", tempfile.mkdtemp(), "-flow_pc_type", "lu",
                    "-flow_pc_factor_mat_solver_type", "nosuch"], capture_output=True, text=True)
check(p.returncode in (2, 3) and p.stderr.count("\n") == 1 and "flow" in p.stderr and "PETSC ERROR" not in p.stderr,
      f"an unknown factorisation package is refused in one line: {p.stderr.strip()!r}")
