#!/usr/bin/python3
"""Is `auto` right on the shipped 3D scenes? Each scene with both systems
direct, both iterative, and `auto`, on 1 and 2 MPI ranks: the wall time and
the coupling iterations each choice costs (an inexact inner solve must not
buy its speed with more coupling iterations than it saves).

The 2D scenes are left out: every one of their systems lies far below the
2D crossovers (docs/performance.md, "Scaling"). No XDMF output. Writes
bench/results/auto.csv (the columns of bench/ranks.py, `variant` being the
solver choice and `scene` the case).
"""
import argparse
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import common  # noqa: E402
import ranks  # noqa: E402
import scaling  # noqa: E402

NAME = "auto"
CASES = {"fracture3d": ("scenes/fracture3d.toml", []),
         "fracture3d_refined": ("scenes/fracture3d.toml", ["mesh.refine=1"]),
         "block3d": ("scenes/block3d.toml", []),
         "indenter3d": ("scenes/indenter3d.toml", [])}
CHOICES = ("direct", "iterative", "auto")
COLUMNS = ["scene"] + ranks.COLUMNS


def parser():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    common.add_arguments(p, NAME)
    p.add_argument("--cases", default=",".join(CASES), help=f"comma-separated subset of {','.join(CASES)}")
    p.add_argument("--ranks", default="1,2", help="comma-separated MPI rank counts (default 1,2)")
    return p


def main():
    args, petsc = common.parse_arguments(parser())
    cases = common.parse_variants(args.cases, CASES)
    rank_counts = [int(r) for r in args.ranks.split(",")]
    os.environ.update(scaling.MPI_ENV)
    header = common.machine_header(args.binary)
    header["petsc_options"] = " ".join(petsc)
    common.print_header(header)
    recorder = common.Recorder(args.out_dir, NAME, COLUMNS, header, args.update)
    with common.WorkDir(args.work_dir, args.keep_runs) as work:
        for case in cases:
            scene, sets = CASES[case]
            for choice in CHOICES:
                for repetition in range(1, args.repeat + 1):
                    for n in rank_counts:
                        run_sets = sets + [f"solver.flow={choice}", f"solver.mechanics={choice}",
                                           "output.xdmf=false"] + args.sets
                        result = common.run_case(common.on_ranks(args.binary, n), os.path.join(common.ROOT, scene),
                                                 run_sets, petsc, work.run(f"{case}-{choice}-{n}-r{repetition}"))
                        row = dict(ranks.row_from_run(3, choice, ("-",), n, repetition, result), scene=case,
                                   cells="-")
                        recorder.add(row)
                        print(f"  {case} {choice} {n} rank(s) #{repetition}: {ranks.described(row)}", flush=True)
    recorder.finish()
    return 0


if __name__ == "__main__":
    sys.exit(common.main_wrapper(main))
