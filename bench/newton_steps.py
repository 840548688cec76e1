#!/usr/bin/python3
"""The contact solves' Newton steps on shipped scenes: per scene (and
scheme) the rows of iterations.csv (coupling iterations of the split, or
solves of a scheme with one solve per step) and the Newton steps in each,
their median, largest and total, the total against summary.json's count
(which adds the initial equilibrium's), and the wall time.

A case is a shipped scene, or SCENE:SCHEME with coupling.scheme = SCHEME.
Writes bench/results/newton_steps.csv, one row per run, and prints a
Markdown table (the first repetition's counts, the median wall time).
"""
import argparse
import csv
import os
import statistics
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import common  # noqa: E402

NAME = "newton_steps"
COLUMNS = ["case", "repetition", "rows", "newton_median", "newton_largest", "newton_total", "summary_newton",
           "wall_s", "command"]
CASES = ("phan,groove,elastic_contact,terzaghi_contact,fault_depletion,fault_reactivation,"
         "fault_reactivation:monolithic,network2d,fault3d,injection_fault3d")


def newton_steps(out):
    """The Newton steps of every row of a run's iterations.csv."""
    with open(os.path.join(out, "iterations.csv")) as f:
        return [int(r["newton_steps"]) for r in csv.DictReader(f)]


def report(rows, cases):
    print("| case | rows | Newton steps per row: median, largest | total (summary.json) | wall (s) |")
    print("| --- | --- | --- | --- | --- |")
    for case in cases:
        runs = [r for r in rows if r["case"] == case]
        r = runs[0]
        wall = statistics.median(x["wall_s"] for x in runs)
        print(f"| {case} | {r['rows']} | {r['newton_median']:g}, {r['newton_largest']} | {r['newton_total']} "
              f"({r['summary_newton']}) | {wall:.2f} |")


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    common.add_arguments(p, NAME)
    p.add_argument("--cases", default=CASES, help=f"SCENE or SCENE:SCHEME, comma-separated (default {CASES})")
    args, petsc = common.parse_arguments(p)
    cases = [c.strip() for c in args.cases.split(",") if c.strip()]
    recorder = common.start_recorder(args, petsc, NAME, COLUMNS, "shipped scenes")
    with common.WorkDir(args.work_dir, args.keep_runs) as work:
        for case in cases:
            scene, _, scheme = case.partition(":")
            sets = args.sets + ([f"coupling.scheme={scheme}"] if scheme else [])
            path = os.path.join(common.ROOT, "scenes", scene + ".toml")
            for repetition in range(1, args.repeat + 1):
                out = work.run(f"{case.replace(':', '-')}-r{repetition}")
                result = common.run_case([args.binary], path, sets, petsc, out)
                steps, s = newton_steps(out), result["summary"]
                recorder.add({"case": case, "repetition": repetition, "rows": len(steps),
                              "newton_median": statistics.median(steps) if steps else 0,
                              "newton_largest": max(steps, default=0), "newton_total": sum(steps),
                              "summary_newton": s.get("newton_iterations"), "wall_s": s["wall_time_s"],
                              "command": result["command"]})
    recorder.finish()
    report(recorder.rows, cases)
    return 0


if __name__ == "__main__":
    sys.exit(common.main_wrapper(main))
