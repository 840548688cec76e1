"""The error-against-run-time study end to end on a tiny study: the CSV has
its columns, every plot is a PNG, errors fall under refinement, the
study's own overrides reach every run, and a study
started again reuses its finished runs. A run reference compares P0 fields
with its average over each coarse cell: on meshes nested by mesh.refine
each coarse cell gets exactly its 4 fine cells, a quarter each; on meshes
that do not nest (mesh.size_factor) it interpolates at each coarse node
from the fine cell holding it; a run against itself has no error (to
round-off)."""
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
overrides = ["time.end=0.32"]
[[levels]]
overrides = ["mesh.cells=[1,5]", "time.dt=0.08"]
[[levels]]
overrides = ["mesh.cells=[1,10]", "time.dt=0.04"]
[[levels]]
overrides = ["mesh.cells=[1,20]", "time.dt=0.02"]
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
    steps = [int(r["steps"]) for r in rows if r["variant"] == variant]
    check(steps == [4, 8, 16], f"{variant}: the study's own overrides (time.end = 0.32) in every run: steps {steps}")
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

# The run reference's cell averages: on meshes nested by mesh.refine
# (gmsh splits each triangle into its 4 children) exactly its 4 fine
# cells, a quarter each; on meshes that do not nest (mesh.size_factor, a
# fault between two sides) each coarse node lies in the fine cell it
# interpolates from, and each coarse cell's weights sum to 1. (The built-in
# meshes cut each square into four at its centre: [2n] does not nest in [n].)
ONE_DAY = ["--set", "time.end=86400.0", "--set", "mesh.size_factor=2.0"]
coarse, _ = run(scene("fault_reactivation"), *ONE_DAY)
fine, _ = run(scene("fault_reactivation"), *ONE_DAY, "--set", "mesh.refine=1")
fields = study_tool.Fields(coarse)
_, average = study_tool.RunReference(fine, "the finer run")._maps_for(fields)
check(np.all(np.diff(average.indptr) == 4) and np.allclose(average.data, 0.25, rtol=1e-14, atol=0),
      "run reference: each coarse cell averages exactly its 4 fine cells, a quarter each")
other, _ = run(scene("fault_reactivation"), *ONE_DAY[:2], "--set", "mesh.size_factor=1.4")
reference = study_tool.RunReference(other, "the finer run")
(vertices, lam), average = reference._maps_for(fields)
x = np.einsum("nk,nkj->nj", lam, reference.fine.nodes[vertices][:, :, :2])
check(lam.min() >= -1e-9 and np.abs(x - fields.nodes[:, :2]).max() <= 1e-9 * np.abs(fields.nodes).max(),
      f"run reference, meshes not nested: every coarse node inside its fine cell (smallest weight {lam.min():.1e}) "
      "and at the weights' point")
check(np.allclose(np.asarray(average.sum(axis=1)).ravel(), 1.0, rtol=1e-12, atol=0),
      "run reference, meshes not nested: each coarse cell's weights sum to 1")
itself = study_tool.errors(fine, study_tool.RunReference(fine, "itself"))
check(max(max(v) for v in itself.values()) <= 1e-14, f"run reference: a run against itself has no error {itself}")

def shipped_study(name, levels_and_variants, column):
    """studies/NAME.toml with its own levels and variants replaced: the
    `column` of results.csv per run and report.md."""
    path = os.path.join(tempfile.mkdtemp(), f"{name}.toml")
    with open(os.path.join(ROOT, "studies", f"{name}.toml")) as f:
        text = f.read()
    with open(path, "w") as f:
        f.write(text[:text.index("[[levels]]")] + levels_and_variants)
    directory = tempfile.mkdtemp()
    p = subprocess.run(["/usr/bin/python3", os.path.join(ROOT, "tools", "study.py"), path, "--out", directory,
                        "--binary", BINARY], capture_output=True, text=True)
    check(p.returncode == 0, f"studies/{name}.toml, two levels, ran ({p.stderr[-300:]!r})")
    with open(os.path.join(directory, "results.csv")) as f:
        rows = list(csv.DictReader(f))
    with open(os.path.join(directory, "report.md")) as f:
        return [float(r[column]) for r in rows], rows, f.read()


# The fault studies: the crack's opening against Sneddon's (2D and the
# penny in 3D), the displaced fault's slip against Jansen and Meulenbroek's
# trapezoid and the conduit's pressure against the erfc fall under
# refinement, and the report gives the observed order.
errs, _, report = shipped_study("sneddon", """[[levels]]
h = 1.0
overrides = ["mesh.refine=0"]
[[levels]]
h = 0.5
overrides = ["mesh.refine=1"]
[[variants]]
label = "default path"
overrides = []
""", "opening_error_final")
check(0 < errs[1] < errs[0] < 0.01 and "| default path | 0 -> 1 |" in report,
      f"a Sneddon study: the opening's error falls under refinement {errs}, the report gives its order")
errs, _, report = shipped_study("jansen_meulenbroek", """[[levels]]
h = 32.0
overrides = ["mesh.file=fault_depletion_coarse.geo", "mesh.refine=0"]
[[levels]]
h = 16.0
overrides = ["mesh.file=fault_depletion_coarse.geo", "mesh.refine=1"]
[[variants]]
label = "full path"
overrides = ["-mechanics_contact_condensed false"]
""", "slip_error_final")
check(0 < errs[1] < errs[0] / 2 ** 1.5 and errs[0] < 0.1 and "| full path | 0 -> 1 |" in report,
      f"a Jansen-Meulenbroek study: the slip's error {errs} falls at an order above 1.5")
errs, rows, report = shipped_study("conduit_transient", """[[levels]]
h = 0.25
dt = 5.0e-5
overrides = ["mesh.refine=0"]
[[levels]]
h = 0.125
dt = 1.25e-5
overrides = ["mesh.refine=1"]
[[variants]]
label = "dt ~ h^2"
overrides = ["time.dt={dt}"]
""", "fault_pressure_error_final")
largest = [float(r["fault_pressure_error_max"]) for r in rows]
check(0 < errs[1] < errs[0] / 2 ** 1.9 and errs[0] < 0.02 and all(m > e for m, e in zip(largest, errs))
      and "| dt ~ h^2 | 0 -> 1 |" in report,
      f"a conduit transient study: the fault pressure's error {errs} falls at an order above 1.9 with dt ~ h^2, "
      f"its maximum over time {largest} above the final one")
errs, _, report = shipped_study("penny", """[[levels]]
h = 0.16
overrides = ["fault.crack.tip_size=0.16"]
[[levels]]
h = 0.08
overrides = ["fault.crack.tip_size=0.08"]
[[variants]]
label = "grading 0.4"
overrides = ["fault.crack.tip_grading=0.4"]
""", "opening_error_final")
check(0 < errs[1] < errs[0] / 1.3 and errs[0] < 0.3 and "| grading 0.4 | 0 -> 1 |" in report,
      f"a penny study: the opening's error {errs} falls as the rim's cells halve")
