#!/usr/bin/python3
"""C++ solver against the Python prototype on the default scene: both wall
times (the summary's, and the process's including start-up), their ratio,
and whether `python_prototype compare` finds the two runs equal.

Per repetition: build/biotcontact run scenes/default.toml --set mesh.cells=[80,8],
/usr/bin/python3 -m python_prototype run (same options), then
/usr/bin/python3 -m python_prototype compare DIR_CPP DIR_PY. Writes
bench/results/prototype.csv. The prototype's first run on a machine also
compiles the forms (cached in ~/.cache/fenics); the median hides it. PETSc
options after `--` go to both runs.
"""
import argparse
import os
import re
import shlex
import subprocess
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import common  # noqa: E402

NAME = "prototype"
SCENE = "scenes/default.toml"
CELLS = (80, 8)
PROTOTYPE = [common.PYTHON, "-m", "python_prototype"]
COLUMNS = ["cells", "unknowns", "repetition", "cpp_wall_s", "cpp_process_wall_s", "py_wall_s", "py_process_wall_s",
           "wall_ratio", "process_wall_ratio", "agree", "max_relative_difference", "coupling_iterations",
           "cpp_peak_rss_mb", "py_peak_rss_mb", "cpp_command", "py_command", "compare_command"]


def compare(dir_cpp, dir_py):
    """Runs `python_prototype compare`; returns (agreed, largest `max
    relative difference` it printed over all fields, command)."""
    command = PROTOTYPE + ["compare", dir_cpp, dir_py]
    text = shlex.join(command)
    print(f"$ {text}", flush=True)
    p = subprocess.run(command, cwd=common.ROOT, capture_output=True, text=True)
    differences = [float(x) for x in re.findall(r"max relative difference\s+(\S+)", p.stdout)]
    if p.returncode not in (0, 1) or not differences:
        raise common.BenchError(f"exit {p.returncode}: {text}: {(p.stderr or p.stdout).strip()[-300:]}")
    lines = [line for line in p.stdout.splitlines() if line.strip()]
    agreed = p.returncode == 0 and lines[-1].strip() == "agree"
    if not agreed:
        print(f"  compare: {lines[-1].strip()}")
    return agreed, max(differences), text


def parser():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    common.add_arguments(p, NAME)
    p.add_argument("--cells", default=common.cells_text(CELLS), help="the mesh (default [80,8])")
    return p


def main():
    args, petsc = common.parse_arguments(parser())
    cells = common.parse_cells(args.cells)
    header = common.machine_header(args.binary)
    header["scene"] = SCENE
    header["fixed_sets"] = " ".join(args.sets)
    header["petsc_options"] = " ".join(petsc)
    header["compare"] = "python_prototype compare, tolerance 1e-8 (relative to each field's largest value)"
    common.print_header(header)
    recorder = common.Recorder(args.out_dir, NAME, COLUMNS, header, args.update)
    scene = os.path.join(common.ROOT, SCENE)
    with common.WorkDir(args.work_dir, args.keep_runs) as work:
        for mesh in cells:
            sets = [f"mesh.cells={common.cells_text(mesh)}"] + args.sets
            for repetition in range(1, args.repeat + 1):
                tag = f"{mesh[0]}x{mesh[1]}-r{repetition}"
                cpp = common.run_case([args.binary], scene, sets, petsc, work.run(f"cpp-{tag}"))
                py = common.run_case(PROTOTYPE, scene, sets, petsc, work.run(f"py-{tag}"))
                agreed, difference, compare_command = compare(os.path.join(work.path, f"cpp-{tag}"),
                                                              os.path.join(work.path, f"py-{tag}"))
                c, p = cpp["summary"], py["summary"]
                row = {"cells": common.cells_text(mesh), "unknowns": sum(c["dofs"].values()),
                       "repetition": repetition, "cpp_wall_s": float(c["wall_time_s"]),
                       "cpp_process_wall_s": cpp["process_wall_s"], "py_wall_s": float(p["wall_time_s"]),
                       "py_process_wall_s": py["process_wall_s"],
                       "wall_ratio": float(p["wall_time_s"]) / float(c["wall_time_s"]),
                       "process_wall_ratio": py["process_wall_s"] / cpp["process_wall_s"],
                       "agree": "yes" if agreed else "no", "max_relative_difference": difference,
                       "coupling_iterations": c["coupling_iterations"], "cpp_peak_rss_mb": cpp["peak_rss_mb"],
                       "py_peak_rss_mb": py["peak_rss_mb"], "cpp_command": cpp["command"],
                       "py_command": py["command"], "compare_command": compare_command}
                recorder.add(row)
                print(f"  {row['cells']} #{repetition}: C++ {row['cpp_wall_s']:.2f} s, prototype "
                      f"{row['py_wall_s']:.2f} s (x{row['wall_ratio']:.2f}); with start-up "
                      f"{row['cpp_process_wall_s']:.2f} / {row['py_process_wall_s']:.2f} s; "
                      f"{'agree' if agreed else 'DIFFER'} ({difference:.1e})", flush=True)
    recorder.finish()
    return 0


if __name__ == "__main__":
    sys.exit(common.main_wrapper(main))
