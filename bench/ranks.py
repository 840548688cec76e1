#!/usr/bin/python3
"""More ranks: every case of the size sweep (2D default scene) and of the
3D scaling (the contact block) with the default solvers, on 1 and on 2 MPI
ranks, one after the other, so that the speed-up is measured in one run;
with --dims faults, the shipped fault scenes as they are.

The rank runs of a case alternate (1, 2, 1, 2, ...), so that a drift of the
machine's speed falls on both; `auto` picks each system's solver, as a
user's run does. Per run: wall time, coupling iterations, the time of each
phase (assembly, set-ups, solves, the contact Schur complement, the rest of
the contact VI, output) and the solvers chosen. Writes
bench/results/ranks.csv.
"""
import argparse
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import common  # noqa: E402
import scaling  # noqa: E402
import size_sweep  # noqa: E402

NAME = "ranks"
# 2D: 9.4e3 to 5.8e5 unknowns, the scene's 48 steps to t = 9.6, variants
# `paper` (single rate) and `monolithic` by default (`kdr` and `multirate4`
# of bench/size_sweep.py take the split's solver paths); 3D: 1.2e4 to 1.0e6
# unknowns, two time steps; faults: every step of each scene (2 ranks never
# slower than 1 with faults). No XDMF output.
SCENES = {2: "scenes/default.toml", 3: "scenes/block3d_box.toml"}
FAULT_SCENES = ("fault_reactivation", "fault_depletion", "sneddon", "sneddon_near", "fault3d", "injection_fault3d",
                "flemisch_regular", "flemisch_complex", "network2d", "berre_regular")
CELLS = {2: [(80, 8), (160, 16), (320, 32), (640, 64)], 3: scaling.CELLS[3] + [scaling.LARGEST[3]]}
SETS = {2: ["output.xdmf=false"], 3: scaling.SETS}
SYSTEMS = ("flow", "mechanics", "monolithic")
PHASES = ("setup", "solve", "schur_complement", "other", "total")
COLUMNS = (["dimension", "variant", "cells", "ranks", "working_ranks", "repetition", "unknowns", "wall_s", "process_wall_s",
            "coupling_iterations", "steps", "assembly_s", "output_s"]
           + [f"{s}_{p}_s" for s in SYSTEMS for p in PHASES]
           + [f"{s}_{c}" for s in SYSTEMS for c in ("linear_iterations", "back_solves", "solver")]
           + ["mechanics_newton_iterations", "active_set_changes", "active_contact_nodes", "peak_rss_mb", "command"])


def row_from_run(dimension, variant, cells, ranks, repetition, result):
    """One CSV row: the summary's phases per system, its counts and the
    solver each system ran ("direct"/"iterative")."""
    s = result["summary"]
    timings, solvers = s.get("timings", {}), s.get("solvers", {})
    row = {"dimension": dimension, "variant": variant, "cells": common.cells_text(cells), "ranks": ranks,
           "working_ranks": s.get("working_ranks", ranks), "repetition": repetition, "unknowns": sum(s["dofs"].values()), "wall_s": float(s["wall_time_s"]),
           "process_wall_s": result["process_wall_s"], "coupling_iterations": s["coupling_iterations"],
           "steps": s["steps"], "assembly_s": float(timings.get("assembly", 0.0)),
           "output_s": float(timings.get("output", 0.0)),
           "mechanics_newton_iterations": solvers.get("mechanics", {}).get("newton_iterations", 0),
           "active_set_changes": sum(solvers.get(x, {}).get("active_set_changes", 0) for x in SYSTEMS),
           "active_contact_nodes": s.get("contact", {}).get("active_nodes", ""),
           "peak_rss_mb": result["peak_rss_mb"], "command": result["command"]}
    for system in SYSTEMS:
        phases, solver = timings.get(system, {}), solvers.get(system, {})
        for phase in PHASES:
            row[f"{system}_{phase}_s"] = float(phases.get(phase, 0.0)) if isinstance(phases, dict) else 0.0
        for count in ("linear_iterations", "back_solves"):
            row[f"{system}_{count}"] = solver.get(count, 0)
        row[f"{system}_solver"] = solver.get("solver", "")
    return row


def described(row):
    """One line of progress for a run's row."""
    return (f"{row['wall_s']:.2f} s, {row['coupling_iterations']} coupling iterations, "
            f"flow {row['flow_solver']}, mechanics {row['mechanics_solver']}")


def parser():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    common.add_arguments(p, NAME)
    p.add_argument("--dims", default="2,3", help="comma-separated dimensions, or faults (default 2,3)")
    p.add_argument("--ranks", default="1,2", help="comma-separated MPI rank counts (default 1,2)")
    p.add_argument("--variants", default="paper,monolithic",
                   help=f"2D variants, a subset of {','.join(size_sweep.VARIANTS)} (default paper,monolithic)")
    p.add_argument("--cells2", help="2D meshes instead of the default list")
    p.add_argument("--cells3", help="3D meshes instead of the default list")
    p.add_argument("--scenes", help="comma-separated fault scenes instead of all of FAULT_SCENES")
    return p


def cases(args):
    """(dimension, variant, cells, scene, sets) of every case, smallest
    first; the fault scenes' variant is the scene's name."""
    variants = common.parse_variants(args.variants, size_sweep.VARIANTS)
    cells = {2: common.parse_cells(args.cells2) if args.cells2 else CELLS[2],
             3: common.parse_cells(args.cells3) if args.cells3 else CELLS[3]}
    result = []
    for dims in args.dims.split(","):
        if dims == "faults":
            names = args.scenes.split(",") if args.scenes else FAULT_SCENES
            if not set(names) <= set(FAULT_SCENES):
                raise common.BenchError(f"--scenes takes some of {', '.join(FAULT_SCENES)}")
            result += [("faults", name, (), f"scenes/{name}.toml", ["output.xdmf=false"] + args.sets)
                       for name in names]
            continue
        if dims not in ("2", "3"):
            raise common.BenchError("--dims takes 2, 3 and faults")
        dimension = int(dims)
        for mesh in cells[dimension]:
            for variant in (variants if dimension == 2 else ["auto"]):
                extra = size_sweep.VARIANTS[variant] if dimension == 2 else []
                result.append((dimension, variant, mesh, SCENES[dimension], [f"mesh.cells={common.cells_text(mesh)}"]
                               + extra + SETS[dimension] + args.sets))
    return result


def main():
    args, petsc = common.parse_arguments(parser())
    ranks = [int(r) for r in args.ranks.split(",")]
    if any(r < 1 for r in ranks):
        raise common.BenchError("--ranks takes positive integers")
    os.environ.update(scaling.MPI_ENV)
    header = common.machine_header(args.binary)
    header["scenes"] = " ".join(list(SCENES.values()) + [f"scenes/{name}.toml" for name in FAULT_SCENES])
    header["petsc_options"] = " ".join(petsc)
    header["solvers"] = "the defaults (solver.flow = solver.mechanics = auto)"
    common.print_header(header)
    recorder = common.Recorder(args.out_dir, NAME, COLUMNS, header, args.update)
    with common.WorkDir(args.work_dir, args.keep_runs) as work:
        for dimension, variant, mesh, path, sets in cases(args):
            scene = os.path.join(common.ROOT, path)
            for repetition in range(1, args.repeat + 1):
                for n in ranks:
                    label = f"{dimension}-{variant}-{'x'.join(map(str, mesh))}-{n}-r{repetition}"
                    row = row_from_run(dimension, variant, mesh, n, repetition,
                                       common.run_case(common.on_ranks(args.binary, n), scene, sets, petsc,
                                                       work.run(label)))
                    recorder.add(row)
                    print(f"  {label}: {row['unknowns']} unknowns, {described(row)}", flush=True)
    recorder.finish()
    return 0


if __name__ == "__main__":
    sys.exit(common.main_wrapper(main))
