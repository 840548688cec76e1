"""The error-against-run-time study end to end on a tiny study: the CSV has
its columns, every plot is a PNG, errors fall under refinement, and a study
started again reuses its finished runs. A run reference compares P0 fields
with its average over each coarse cell: on meshes nested by halving h each
coarse cell gets exactly its 4 fine cells (their areas sum to its own), and
a run against itself has no error (to round-off)."""
import csv
import os
import subprocess
import sys
import tempfile

import numpy as np

from support import BINARY, ROOT, check, run, scene

sys.path.insert(0, os.path.join(ROOT, "tools"))
import study as study_tool  # noqa: E402

study = os.path.join(tempfile.mkdtemp(), "tiny.toml")
with open(study, "w") as f:
    f.write('''name = "tiny"
scene = "scenes/terzaghi.toml"
reference = "closed-form"
[[levels]]
overrides = ["mesh.cells=[1,5]", "time.dt=0.08", "time.end=0.32"]
[[levels]]
overrides = ["mesh.cells=[1,10]", "time.dt=0.04", "time.end=0.32"]
[[levels]]
overrides = ["mesh.cells=[1,20]", "time.dt=0.02", "time.end=0.32"]
[[variants]]
label = "monolithic"
overrides = ["coupling.scheme=monolithic"]
[[variants]]
label = "fixed stress"
overrides = ["coupling.scheme=fixed-stress"]
''')
out = tempfile.mkdtemp()
command = ["/usr/bin/python3", os.path.join(ROOT, "tools", "study.py"), study, "--out", out, "--binary", BINARY]
p = subprocess.run(command, capture_output=True, text=True)
check(p.returncode == 0, f"the study ran: {p.stderr[-500:]}")
check("[6/6]" in p.stdout and "left" in p.stdout, "progress shows the run count and the time left")
with open(os.path.join(out, "results.csv")) as f:
    rows = list(csv.DictReader(f))
needed = {"variant", "scheme", "q", "L", "h", "dt", "dofs", "steps", "coupling_iterations", "flow_solves",
          "mechanics_solves", "wall_time_s", "pressure_error_final", "pressure_error_max",
          "displacement_error_final", "flux_error_final", "reference"}
check(len(rows) == 6 and needed <= set(rows[0]), f"results.csv has 6 rows and the columns {sorted(needed)}")
for name in ("error_vs_time.png", "work_vs_error.png", "iterations_vs_gamma.png", "contraction.png"):
    with open(os.path.join(out, name), "rb") as f:
        check(f.read(8) == b"\x89PNG\r\n\x1a\n", f"{name} is a PNG")
for variant in ("monolithic", "fixed stress"):
    errs = [float(r["pressure_error_final"]) for r in rows if r["variant"] == variant]
    check(errs[0] > errs[1] > errs[2] > 0, f"{variant}: pressure error falls under refinement {errs}")
    errs = [float(r["displacement_error_final"]) for r in rows if r["variant"] == variant]
    check(errs[0] > errs[1] > errs[2] > 0, f"{variant}: displacement error falls under refinement {errs}")
with open(os.path.join(out, "report.md")) as f:
    report = f.read()
check("machine:" in report and "Fastest run" in report and "error_vs_time.png" in report, "report.md is complete")
p = subprocess.run(command, capture_output=True, text=True)
with open(os.path.join(out, "results.csv")) as f:
    again = list(csv.DictReader(f))
check(p.returncode == 0 and all(r["cached"] == "True" for r in again), "a second start reuses every finished run")

# The run reference's cell averages, on two nested meshes of the default scene.
SHORT = ["--set", "time.end=0.4", "--set", "coupling.scheme=monolithic"]
coarse, _ = run(scene("default"), "--set", "mesh.cells=[20,2]", *SHORT)
fine, _ = run(scene("default"), "--set", "mesh.cells=[40,4]", *SHORT)
reference = study_tool.RunReference(fine, "the finer run")
fields = study_tool.Fields(coarse)
_, owner, weights = reference._maps_for(fields)
check(np.all(np.bincount(owner, minlength=len(fields.cells)) == 4)
      and np.allclose(weights, study_tool.cell_areas(fields), rtol=1e-12, atol=0),
      "run reference: each coarse cell averages exactly its 4 fine cells, whose areas sum to its own")
itself = study_tool.errors(fine, study_tool.RunReference(fine, "itself"))
check(max(max(v) for v in itself.values()) <= 1e-14, f"run reference: a run against itself has no error {itself}")

# A fault study (reference = "sneddon"): the crack's opening against
# Sneddon's ellipse falls under refinement, and the report gives its
# observed order.
sneddon = os.path.join(tempfile.mkdtemp(), "crack.toml")
with open(os.path.join(ROOT, "studies", "sneddon.toml")) as f:
    text = f.read()
with open(sneddon, "w") as f:
    f.write(text[:text.index("[[levels]]")] + """[[levels]]
h = 1.0
overrides = ["mesh.refine=0"]
[[levels]]
h = 0.5
overrides = ["mesh.refine=1"]
[[variants]]
label = "default path"
overrides = []
""")
crack = tempfile.mkdtemp()
p = subprocess.run(["/usr/bin/python3", os.path.join(ROOT, "tools", "study.py"), sneddon, "--out", crack,
                    "--binary", BINARY], capture_output=True, text=True)
with open(os.path.join(crack, "results.csv")) as f:
    errs = [float(r["opening_error_final"]) for r in csv.DictReader(f)]
with open(os.path.join(crack, "report.md")) as f:
    report = f.read()
check(p.returncode == 0 and 0 < errs[1] < errs[0] < 0.01 and "| default path | 0 -> 1 |" in report,
      f"a Sneddon study: the opening's error falls under refinement {errs}, the report gives its order "
      f"({p.stderr[-300:]!r})")
