#!/usr/bin/python3
"""Scaling of the solvers: direct against iterative ([solver]), on 1 and 2
MPI ranks, over mesh sizes in 2D and 3D, for a short run (two time steps).

Per run: wall time, coupling iterations, time per coupling iteration and per
unknown, linear iterations per solve (flow: per back-solve; mechanics: per
Newton step of the contact VI), preconditioner set-ups, peak memory of the
largest process. Writes bench/results/scaling.csv.
"""
import argparse
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import common  # noqa: E402

NAME = "scaling"
# 2D: 9.4e3 to 5.8e5 unknowns (--largest: 2.3e6); 3D: 1.2e4 to 3.0e5
# (--largest: 1.0e6). The direct path is skipped above --direct-limit2 /
# --direct-limit3 unknowns (defaults 3e6 and 4e5: a 3D factorisation at 7e5
# unknowns takes about ten minutes and 5 GB, which is the point of the
# iterative path). Two time steps without XDMF output.
SCENES = {2: "scenes/default.toml", 3: "scenes/block3d_box.toml"}
CELLS = {2: [(80, 8), (160, 16), (320, 32), (640, 64)], 3: [(16, 8, 4), (24, 12, 6), (32, 16, 8), (48, 24, 12)]}
LARGEST = {2: (1280, 128), 3: (72, 36, 18)}
SETS = ["time.end=0.4", "output.xdmf=false"]
COLUMNS = ["dimension", "cells", "solver", "ranks", "repetition", "unknowns", "flow_unknowns", "mechanics_unknowns",
           "wall_s", "coupling_iterations", "time_per_iteration_ms", "us_per_unknown_per_iteration",
           "flow_iterations_per_solve", "mechanics_iterations_per_newton_step", "flow_setups", "mechanics_setups",
           "active_set_changes", "flow_total_s", "mechanics_total_s", "flow_setup_s", "mechanics_setup_s",
           "flow_solve_s", "mechanics_solve_s", "mechanics_schur_complement_s", "mechanics_other_s", "assembly_s",
           "output_s", "flow_linear_iterations", "mechanics_linear_iterations", "mechanics_newton_iterations",
           "flow_method", "mechanics_method", "peak_rss_mb", "kb_per_unknown", "command"]
MPI_ENV = {"OMPI_ALLOW_RUN_AS_ROOT": "1", "OMPI_ALLOW_RUN_AS_ROOT_CONFIRM": "1",
           "OMPI_MCA_rmaps_base_oversubscribe": "1"}


def row_from_run(dimension, cells, solver, ranks, repetition, result):
    s = result["summary"]
    solvers, timings = s["solvers"], s["timings"]
    flow, mechanics = solvers["flow"], solvers["mechanics"]
    unknowns = sum(s["dofs"].values())
    iterations = s["coupling_iterations"]
    wall = float(s["wall_time_s"])
    return {"dimension": dimension, "cells": common.cells_text(cells), "solver": solver, "ranks": ranks,
            "repetition": repetition, "unknowns": unknowns, "flow_unknowns": flow["unknowns"],
            "mechanics_unknowns": mechanics["unknowns"], "wall_s": wall, "coupling_iterations": iterations,
            "time_per_iteration_ms": 1e3 * wall / iterations,
            "us_per_unknown_per_iteration": 1e6 * wall / iterations / unknowns,
            "flow_iterations_per_solve": flow["linear_iterations"] / flow["back_solves"],
            "mechanics_iterations_per_newton_step": mechanics["linear_iterations"] / mechanics["newton_iterations"],
            "flow_setups": flow["preconditioner_setups"], "mechanics_setups": mechanics["preconditioner_setups"],
            "active_set_changes": mechanics["active_set_changes"],
            "flow_total_s": timings["flow"]["total"], "mechanics_total_s": timings["mechanics"]["total"],
            "flow_setup_s": timings["flow"]["setup"], "mechanics_setup_s": timings["mechanics"]["setup"],
            "flow_solve_s": timings["flow"]["solve"], "mechanics_solve_s": timings["mechanics"]["solve"],
            "mechanics_schur_complement_s": timings["mechanics"]["schur_complement"],
            "mechanics_other_s": timings["mechanics"]["other"], "assembly_s": timings["assembly"],
            "output_s": timings["output"], "flow_linear_iterations": flow["linear_iterations"],
            "mechanics_linear_iterations": mechanics["linear_iterations"],
            "mechanics_newton_iterations": mechanics["newton_iterations"],
            "flow_method": flow["method"], "mechanics_method": mechanics["method"],
            "peak_rss_mb": result["peak_rss_mb"], "kb_per_unknown": 1024 * result["peak_rss_mb"] / unknowns,
            "command": result["command"]}


def parser():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    common.add_arguments(p, NAME)
    p.add_argument("--dims", default="2,3", help="comma-separated dimensions (default 2,3)")
    p.add_argument("--solvers", default="direct,iterative",
                   help="comma-separated subset of direct,iterative,auto (auto: the defaults' own choice)")
    p.add_argument("--ranks", default="1,2", help="comma-separated MPI rank counts (default 1,2)")
    p.add_argument("--cells2", help="2D meshes instead of the default list")
    p.add_argument("--cells3", help="3D meshes instead of the default list")
    p.add_argument("--largest", action="store_true", help="also run the largest mesh of each dimension")
    p.add_argument("--direct-limit2", type=float, default=3e6,
                   help="2D: skip the direct path above this many unknowns (default 3e6)")
    p.add_argument("--direct-limit3", type=float, default=4e5,
                   help="3D: skip the direct path above this many unknowns (default 4e5)")
    return p


def estimated_unknowns(dimension, cells):
    """Unknowns of the coupled problem on the built-in mesh (P1 vector,
    RT0 facets, P0 cells), to skip cases before running them. The rectangle
    has crossed diagonals (4 triangles and a centre node per quadrilateral),
    the box 6 tetrahedra per hexahedron."""
    if dimension == 2:
        nx, ny = cells
        nodes, triangles = (nx + 1) * (ny + 1) + nx * ny, 4 * nx * ny
        return 2 * nodes + (nodes + triangles - 1) + triangles
    nx, ny, nz = cells
    nodes, tetrahedra = (nx + 1) * (ny + 1) * (nz + 1), 6 * nx * ny * nz
    faces = 2 * tetrahedra + (2 * (nx * ny + ny * nz + nx * nz))  # interior faces counted once, plus boundary
    return 3 * nodes + faces + tetrahedra


def main():
    args, petsc = common.parse_arguments(parser())
    dims = [int(d) for d in args.dims.split(",")]
    solvers = common.parse_variants(args.solvers, ("direct", "iterative", "auto"))
    ranks = [int(r) for r in args.ranks.split(",")]
    if any(d not in SCENES for d in dims) or any(r < 1 for r in ranks):
        raise common.BenchError("--dims takes 2 and 3, --ranks positive integers")
    cells = {2: common.parse_cells(args.cells2) if args.cells2 else CELLS[2] + ([LARGEST[2]] if args.largest else []),
             3: common.parse_cells(args.cells3) if args.cells3 else CELLS[3] + ([LARGEST[3]] if args.largest else [])}
    os.environ.update(MPI_ENV)
    header = common.machine_header(args.binary)
    header["scenes"] = " ".join(SCENES[d] for d in dims)
    header["fixed_sets"] = " ".join(SETS + args.sets)
    header["petsc_options"] = " ".join(petsc)
    header["iteration"] = "coupling iteration of the fixed-stress split"
    limit = {2: args.direct_limit2, 3: args.direct_limit3}
    header["direct_limit"] = f"2D {limit[2]:g}, 3D {limit[3]:g} unknowns"
    common.print_header(header)
    recorder = common.Recorder(args.out_dir, NAME, COLUMNS, header, args.update)
    with common.WorkDir(args.work_dir, args.keep_runs) as work:
        for dimension in dims:
            scene = os.path.join(common.ROOT, SCENES[dimension])
            for mesh in cells[dimension]:
                for solver in solvers:
                    if solver == "direct" and estimated_unknowns(dimension, mesh) > limit[dimension]:
                        print(f"  skipped: direct at {common.cells_text(mesh)} (above --direct-limit{dimension})")
                        continue
                    for n in ranks:
                        prefix = common.on_ranks(args.binary, n)
                        sets = [f"mesh.cells={common.cells_text(mesh)}", f"solver.flow={solver}",
                                f"solver.mechanics={solver}"] + SETS + args.sets
                        for repetition in range(1, args.repeat + 1):
                            label = f"{dimension}d-{'x'.join(map(str, mesh))}-{solver}-{n}-r{repetition}"
                            row = row_from_run(dimension, mesh, solver, n, repetition,
                                               common.run_case(prefix, scene, sets, petsc, work.run(label)))
                            recorder.add(row)
                            print(f"  {label}: {row['unknowns']} unknowns, {row['wall_s']:.2f} s, "
                                  f"{row['time_per_iteration_ms']:.3g} ms/iteration, "
                                  f"{row['us_per_unknown_per_iteration']:.3g} us/unknown/iteration, "
                                  f"its/solve flow {row['flow_iterations_per_solve']:.1f} "
                                  f"mechanics {row['mechanics_iterations_per_newton_step']:.1f}, "
                                  f"{row['peak_rss_mb']:.0f} MB", flush=True)
    recorder.finish()
    return 0


if __name__ == "__main__":
    sys.exit(common.main_wrapper(main))
