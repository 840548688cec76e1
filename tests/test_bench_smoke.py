"""The benchmark scripts (bench/) end to end on tiny settings: each writes
its CSV with the header lines and the expected columns, and report.py turns
them into a report with the targets table and plots, keeps a hand-written
analysis block, and refreshes the measured block of a page given with
--measured. Nothing is written to bench/results or docs/."""
import os
import shutil
import subprocess
import sys
import tempfile

from support import BINARY, ROOT, check

sys.path.insert(0, os.path.join(ROOT, "bench"))
import common  # noqa: E402

PY = "/usr/bin/python3"
results = tempfile.mkdtemp(prefix="bench-smoke-")
docs = os.path.join(results, "docs")
os.makedirs(docs)
output = os.path.join(docs, "performance.md")
STALE = "stale-block-7f3e9c"


def bench(script, *options):
    command = [PY, os.path.join(ROOT, "bench", script), *options]
    p = subprocess.run(command, capture_output=True, text=True, timeout=120)
    text = f"bench/{script} {' '.join(options)}"
    check(p.returncode == 0, f"{text} ran" if p.returncode == 0 else f"{text} exited {p.returncode}: {p.stderr[-800:]}")
    return p.stdout


common_options = ["--repeat", "1", "--binary", BINARY, "--out-dir", results]
out = bench("size_sweep.py", "--cells", "[20,2]", "--set", "time.end=0.8", *common_options)
check("commit:" in out and "$ " in out and "--set output.xdmf=false" in out,
      "size_sweep prints the header and the commands it runs")
out = bench("mandel.py", "--cells", "[20,2]", *common_options)
out = bench("builds.py", "--before", BINARY, "--scenes", "default", "--set", "time.end=0.8",
            *common_options)
check("| default |" in out, "bench/builds.py prints the table of two builds")
out = bench("newton_steps.py", "--cases", "default,default:monolithic", "--set", "time.end=0.4", *common_options)
check("| default:monolithic | 2 | " in out,
      "bench/newton_steps.py counts a row per monolithic step and prints the Newton steps' table")
out = bench("network.py", "--faults", "4", "--ranks", "1", "--set", "time.end=86400.0", *common_options)
check("ratio" in out, "bench/network.py runs a network and its single fracture and prints their ratio")
out = bench("prototype.py", "--cells", "[20,2]", "--set", "time.end=0.8", *common_options)
check("python_prototype compare" in out, "prototype.py prints the compare command")
out = bench("scaling.py", "--cells2", "[20,2]", "--cells3", "[4,2,2]", *common_options)
check("mpirun -n 2" in out and "solver.mechanics=iterative" in out,
      "scaling.py runs both solvers on 1 and 2 ranks and prints the commands")
out = bench("ranks.py", "--cells2", "[20,2]", "--cells3", "[4,2,2]", "--variants", "paper,monolithic",
            "--set", "time.end=0.4", *common_options)
check("mpirun -n 2" in out, "ranks.py runs every case on 1 and 2 ranks and prints the commands")

expected = {
    "size_sweep": ({"variant", "cells", "unknowns", "repetition", "wall_s", "coupling_iterations",
                    "time_per_iteration_ms", "flow_setup_s", "flow_solve_s", "flow_other_s", "flow_total_s",
                    "mechanics_solve_s", "monolithic_total_s", "assembly_s", "output_s", "flow_factorizations",
                    "mechanics_factorizations", "monolithic_factorizations", "active_set_changes",
                    "mechanics_back_solves", "peak_rss_mb", "solve_phase_ms_per_iteration",
                    "iteration_to_solve_ratio"}, 4),
    "network": ({"case", "ranks", "repetition", "wall_s", "step_s", "unknowns", "faults", "steps"}, 2),
    "mandel": ({"variant", "cells", "dt", "repetition", "wall_s", "pressure_error", "unknowns"}, 2),
    "prototype": ({"cells", "repetition", "cpp_wall_s", "py_wall_s", "cpp_process_wall_s", "py_process_wall_s",
                   "wall_ratio", "agree", "max_relative_difference"}, 1),
    "scaling": ({"dimension", "cells", "solver", "ranks", "unknowns", "wall_s", "us_per_unknown_per_iteration",
                 "flow_iterations_per_solve", "mechanics_iterations_per_newton_step", "mechanics_setups",
                 "peak_rss_mb"}, 8),
    "ranks": ({"dimension", "variant", "cells", "ranks", "unknowns", "wall_s", "coupling_iterations", "assembly_s",
               "flow_solve_s", "mechanics_schur_complement_s", "monolithic_total_s", "flow_solver",
               "peak_rss_mb"}, 6),
}
for name, (columns, count) in expected.items():
    header, rows = common.read_csv(os.path.join(results, name + ".csv"))
    check(len(rows) == count and columns <= set(rows[0]),
          f"{name}.csv: {count} rows with the columns {sorted(columns)}")
    check({"host", "cores", "cpu", "date", "commit", "dirty", "solver", "command"} <= set(header)
          and header["status"] == "complete", f"{name}.csv: machine header lines, status complete")
    check(all(float(r.get("peak_rss_mb", r.get("cpp_peak_rss_mb"))) > 1 for r in rows),
          f"{name}.csv: peak memory recorded")

_, sweep = common.read_csv(os.path.join(results, "size_sweep.csv"))
check({r["variant"] for r in sweep} == {"paper", "kdr", "multirate4", "monolithic"}, "all four sweep variants ran")
_, mandel = common.read_csv(os.path.join(results, "mandel.csv"))
errors = [float(r["pressure_error"]) for r in mandel]
check(all(0 < e < 0.1 for e in errors) and abs(errors[0] - errors[1]) <= 1e-6 * errors[0],
      f"Mandel pressure errors {errors} small and equal for split and monolithic")
_, proto = common.read_csv(os.path.join(results, "prototype.csv"))
check(proto[0]["agree"] == "yes", "C++ and prototype agree")

with open(output, "w") as f:
    # A marker no report can contain by chance (the CPU line "Intel Xeon Gold" holds "old").
    f.write(f"{STALE}\n<!-- analysis begin -->\nHand-written: keep me.\n<!-- analysis end -->\n{STALE}\n")
readme = os.path.join(docs, "README.md")
with open(readme, "w") as f:
    f.write(f"intro\n<!-- measured begin -->\n{STALE}\n<!-- measured end -->\nrest\n")
bench("report.py", "--results", results, "--output", output, "--measured", readme)
with open(output) as f:
    report = f.read()
check("## Targets" in report and "| target | goal | baseline | measured (median) | status |" in report
      and "default [160,16], single rate L = paper" in report and "Mandel: pressure error" in report,
      "the report has the targets table")
check("Hand-written: keep me." in report and STALE not in report, "the analysis block is kept, the rest replaced")
check(all(s in report for s in ("## Size sweep", "## Mandel", "## C++ against the Python prototype",
                                 "## Scaling", "`auto` picks the faster method", "## More ranks",
                                 "2 ranks never slower than 1", "### Extrapolation to a cluster")),
      "the report has a section per benchmark")
for name in ("wall_vs_unknowns.png", "time_per_iteration.png", "memory_vs_unknowns.png", "mandel_error_vs_wall.png",
             "scaling.png", "ranks.png"):
    with open(os.path.join(docs, "performance", name), "rb") as f:
        check(f.read(8) == b"\x89PNG\r\n\x1a\n", f"{name} is a PNG")
with open(readme) as f:
    text = f.read()
check(STALE not in text and "| target |" in text and text.startswith("intro") and text.endswith("rest\n"),
      "--measured replaces only the measured block")
shutil.rmtree(results)
