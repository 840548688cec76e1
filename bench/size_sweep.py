#!/usr/bin/python3
"""Size sweep: the default scene on refined meshes with four coupling
variants, timing every phase of the run and its peak memory.

Cells [40,4], [80,8], [160,16], [320,32] (and [640,64] with --largest);
variants: single rate L = alpha^2/lambda (`paper`, the scene default), single
rate L = alpha^2/K_dr (`kdr`), multirate q = 4 (`multirate4`) and the
monolithic solve (`monolithic`). Every run has output.xdmf=false (the sweep
times the solve, not the output). Writes bench/results/size_sweep.csv, one
row per run and repetition.
"""
import argparse
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import common  # noqa: E402

NAME = "size_sweep"
SCENE = "scenes/default.toml"
CELLS = [(40, 4), (80, 8), (160, 16), (320, 32)]
LARGEST = (640, 64)
VARIANTS = {
    "paper": [],
    "kdr": ["coupling.L=kdr"],
    "multirate4": ["coupling.scheme=multirate", "coupling.q=4"],
    "monolithic": ["coupling.scheme=monolithic"],
}
SYSTEMS = ("flow", "mechanics", "monolithic")
PHASES = ("setup", "solve", "schur_complement", "other", "total", "matrix_assembly")
COLUMNS = (["variant", "cells", "unknowns", "repetition", "wall_s", "process_wall_s", "steps",
            "coupling_iterations", "time_per_iteration_ms", "solve_phase_ms_per_iteration",
            "iteration_to_solve_ratio", "iteration_to_back_solve_ratio"]
           + [f"{s}_{p}_s" for s in SYSTEMS for p in PHASES]
           + ["assembly_s", "output_s"]
           + [f"{s}_factorizations" for s in SYSTEMS] + ["active_set_changes"]
           + [f"{s}_back_solves" for s in SYSTEMS] + ["peak_rss_mb", "command"])


def row_from_run(variant, cells, repetition, result):
    """One CSV row from a run: the summary's timings per system and phase,
    solver counts, and the per-iteration costs. An iteration is a coupling
    iteration of the split, or a time step of the monolithic solve; the solve
    phase is the time in the factorised solves (flow + mechanics, or
    monolithic)."""
    s = result["summary"]
    timings, solvers = s.get("timings", {}), s.get("solvers", {})
    row = {"variant": variant, "cells": common.cells_text(cells), "unknowns": sum(s["dofs"].values()),
           "repetition": repetition, "wall_s": float(s["wall_time_s"]),
           "process_wall_s": result["process_wall_s"], "steps": s["steps"],
           "coupling_iterations": s["coupling_iterations"], "assembly_s": float(timings.get("assembly", 0.0)),
           "output_s": float(timings.get("output", 0.0)), "peak_rss_mb": result["peak_rss_mb"],
           "command": result["command"]}
    for system in SYSTEMS:
        phases = timings.get(system, {})
        for phase in PHASES:
            row[f"{system}_{phase}_s"] = float(phases.get(phase, 0.0)) if isinstance(phases, dict) else 0.0
        solver = solvers.get(system, {})
        row[f"{system}_factorizations"] = solver.get("factorizations", 0)
        row[f"{system}_back_solves"] = solver.get("back_solves", 0)
    row["active_set_changes"] = sum(solvers.get(x, {}).get("active_set_changes", 0) for x in SYSTEMS)
    iterations = s["steps"] if variant == "monolithic" else s["coupling_iterations"]
    solve = sum(row[f"{system}_solve_s"] for system in SYSTEMS)
    row["time_per_iteration_ms"] = 1e3 * row["wall_s"] / iterations if iterations else float("nan")
    row["solve_phase_ms_per_iteration"] = 1e3 * solve / iterations if iterations else float("nan")
    row["iteration_to_solve_ratio"] = row["wall_s"] / solve if solve > 0 else float("nan")
    # The yardstick: one back-solve of each system per iteration
    # (a condensed contact solve makes two of the mechanics').
    one_each = sum(row[f"{system}_solve_s"] / row[f"{system}_back_solves"]
                   for system in SYSTEMS if row[f"{system}_back_solves"])
    row["iteration_to_back_solve_ratio"] = (row["wall_s"] / (iterations * one_each)
                                            if iterations and one_each > 0 else float("nan"))
    return row


def parser():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    common.add_arguments(p, NAME)
    p.add_argument("--cells", help='restrict to these meshes, e.g. "[40,4],[80,8]" (any size is accepted)')
    p.add_argument("--variants", default=",".join(VARIANTS),
                   help=f"comma-separated subset of {','.join(VARIANTS)}")
    p.add_argument("--largest", action="store_true", help=f"also run {common.cells_text(LARGEST)}")
    return p


def main():
    args, petsc = common.parse_arguments(parser())
    variants = common.parse_variants(args.variants, VARIANTS)
    cells = common.parse_cells(args.cells) if args.cells else CELLS + ([LARGEST] if args.largest else [])
    header = common.machine_header(args.binary)
    header["scene"] = SCENE
    header["fixed_sets"] = " ".join(["output.xdmf=false"] + args.sets)
    header["petsc_options"] = " ".join(petsc)
    header["iteration"] = "coupling iteration (split) or time step (monolithic)"
    common.print_header(header)
    recorder = common.Recorder(args.out_dir, NAME, COLUMNS, header, args.update)
    scene = os.path.join(common.ROOT, SCENE)
    with common.WorkDir(args.work_dir, args.keep_runs) as work:
        for mesh in cells:
            for variant in variants:
                sets = [f"mesh.cells={common.cells_text(mesh)}", "output.xdmf=false"] + VARIANTS[variant] + args.sets
                for repetition in range(1, args.repeat + 1):
                    out = work.run(f"{variant}-{mesh[0]}x{mesh[1]}-r{repetition}")
                    row = row_from_run(variant, mesh, repetition,
                                       common.run_case([args.binary], scene, sets, petsc, out))
                    recorder.add(row)
                    print(f"  {variant} {row['cells']} #{repetition}: {row['wall_s']:.2f} s, "
                          f"{row['time_per_iteration_ms']:.3g} ms/iteration "
                          f"({row['iteration_to_solve_ratio']:.2f} x solve, "
                          f"{row['iteration_to_back_solve_ratio']:.2f} x one back-solve each), {row['peak_rss_mb']:.0f} MB", flush=True)
    recorder.finish()
    return 0


if __name__ == "__main__":
    sys.exit(common.main_wrapper(main))
