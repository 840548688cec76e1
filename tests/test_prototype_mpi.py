"""The Python prototype on two MPI ranks agrees with the C++ solver on one
rank (default contact scene): fields within 1e-8 relative at every output
time, identical coupling iterations and active contact sets."""
import subprocess
import tempfile

from support import EVERY_RANK, MPI_ENV, ROOT, check, mpirun, run, scene, summary

cpp, _ = run(scene("default"))
py = tempfile.mkdtemp(prefix="biotcontact-py-")
env = dict(MPI_ENV, PYTHONPATH=ROOT)
p = subprocess.run([*mpirun(2), "/usr/bin/python3", "-m", "python_prototype", "run", scene("default"),
                    "--out", py, *EVERY_RANK], capture_output=True, text=True, env=env, timeout=900)
check(p.returncode == 0, f"the prototype runs on two ranks ({p.stderr.strip()[-300:]})")
check(summary(py)["mpi_ranks"] == 2, "the prototype used two ranks")
c = subprocess.run(["/usr/bin/python3", "-m", "python_prototype", "compare", cpp, py, "--tolerance", "1e-8"],
                   capture_output=True, text=True, env=env)
print(c.stdout, end="")
check(c.returncode == 0, "two-rank prototype vs one-rank C++: fields within 1e-8, same iterations and contact sets")
