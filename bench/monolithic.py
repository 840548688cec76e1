#!/usr/bin/python3
"""The monolithic system solved by its factorisation and by FGMRES
preconditioned by the fixed-stress split, against the iterative split, over
mesh sizes: bench/scaling.py's scenes and meshes (2D: the default contact
scene, [80,8] .. [320,32]; 3D: scenes/block3d_box.toml, [16,8,4] ..
[48,24,12]), two time steps (time.end = 0.4), one rank, no XDMF. Variants:
`split` (solver.flow = solver.mechanics = "iterative"), `direct` and
`iterative` (coupling.scheme = "monolithic" with that solver.monolithic).
Per run: wall time, the contact VI's Newton steps, Krylov iterations per
Newton step, preconditioner set-ups, peak memory. Writes
bench/results/monolithic.csv.
"""
import argparse
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import common  # noqa: E402
from scaling import SCENES, SETS  # noqa: E402  (the same scenes and two steps)

NAME = "monolithic"
CELLS = {2: [(80, 8), (160, 16), (320, 32)], 3: [(16, 8, 4), (24, 12, 6), (32, 16, 8), (48, 24, 12)]}
VARIANT_SETS = {"split": ["solver.flow=iterative", "solver.mechanics=iterative"],
                "direct": ["coupling.scheme=monolithic", "solver.monolithic=direct"],
                "iterative": ["coupling.scheme=monolithic", "solver.monolithic=iterative"]}
COLUMNS = ["dimension", "cells", "variant", "repetition", "unknowns", "wall_s", "coupling_iterations",
           "newton_steps", "krylov_iterations_per_newton_step", "setups", "active_set_changes", "peak_rss_mb",
           "command"]


def row_from_run(dimension, cells, variant, repetition, result):
    s = result["summary"]
    solvers = s["solvers"]
    systems = ["monolithic"] if variant != "split" else ["mechanics"]
    newton = sum(solvers[x]["newton_iterations"] for x in systems)
    linear = sum(solvers[x]["linear_iterations"] for x in systems)
    return {"dimension": dimension, "cells": common.cells_text(cells), "variant": variant, "repetition": repetition,
            "unknowns": sum(s["dofs"].values()), "wall_s": float(s["wall_time_s"]),
            "coupling_iterations": s["coupling_iterations"], "newton_steps": newton,
            "krylov_iterations_per_newton_step": linear / newton if newton else "",
            "setups": sum(solvers[x]["preconditioner_setups"] for x in solvers),
            "active_set_changes": sum(solvers[x]["active_set_changes"] for x in systems),
            "peak_rss_mb": result["peak_rss_mb"], "command": result["command"]}


def parser():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    common.add_arguments(p, NAME)
    p.add_argument("--dims", default="2,3", help="comma-separated dimensions (default 2,3)")
    p.add_argument("--variants", default="split,direct,iterative", help="comma-separated subset of "
                   "split,direct,iterative")
    p.add_argument("--cells2", help="2D meshes instead of the default list")
    p.add_argument("--cells3", help="3D meshes instead of the default list")
    return p


def main():
    args, petsc = common.parse_arguments(parser())
    dims = [int(d) for d in args.dims.split(",")]
    variants = common.parse_variants(args.variants, tuple(VARIANT_SETS))
    if any(d not in SCENES for d in dims):
        raise common.BenchError("--dims takes 2 and 3")
    cells = {2: common.parse_cells(args.cells2) if args.cells2 else CELLS[2],
             3: common.parse_cells(args.cells3) if args.cells3 else CELLS[3]}
    header = common.machine_header(args.binary)
    header["scenes"] = " ".join(SCENES[d] for d in dims)
    header["fixed_sets"] = " ".join(SETS + args.sets)
    header["petsc_options"] = " ".join(petsc)
    common.print_header(header)
    recorder = common.Recorder(args.out_dir, NAME, COLUMNS, header, args.update)
    with common.WorkDir(args.work_dir, args.keep_runs) as work:
        for dimension in dims:
            scene = os.path.join(common.ROOT, SCENES[dimension])
            for mesh in cells[dimension]:
                for variant in variants:
                    sets = [f"mesh.cells={common.cells_text(mesh)}"] + VARIANT_SETS[variant] + SETS + args.sets
                    for repetition in range(1, args.repeat + 1):
                        label = f"{dimension}d-{'x'.join(map(str, mesh))}-{variant}-r{repetition}"
                        row = row_from_run(dimension, mesh, variant, repetition,
                                           common.run_case([args.binary], scene, sets, petsc, work.run(label)))
                        recorder.add(row)
                        print(f"  {label}: {row['unknowns']} unknowns, {row['wall_s']:.2f} s, "
                              f"{row['newton_steps']} Newton steps, "
                              f"{row['krylov_iterations_per_newton_step'] or 0:.1f} its/step, "
                              f"{row['peak_rss_mb']:.0f} MB", flush=True)
    recorder.finish()
    return 0


if __name__ == "__main__":
    sys.exit(common.main_wrapper(main))
