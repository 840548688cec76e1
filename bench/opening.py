#!/usr/bin/python3
"""The split through a conduit fault's opening: the injections into
scenes/fault_reactivation.toml's frictional conduit (test_friction_opening's
well, coupling.tolerance 1e-10, coupling.max_iterations 400; on 22.5-minute
and 3-hour BDF2 steps with and without time.retry, and with
coupling.fallback, single-rate and multirate with q = 2) and into scenes/injection_fault3d.toml at ten and
twenty times its rate. Per case the status, the steps done, the retries
and fallback steps, the coupling iterations and the most in a step, and
the wall time; a failed run is a result too (its summary.json says how
far it came).

Writes bench/results/opening.csv and prints a Markdown table.
"""
import argparse
import csv
import json
import os
import statistics
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import common  # noqa: E402
import markdown  # noqa: E402

NAME = "opening"
COLUMNS = ["case", "repetition", "status", "steps", "retries", "fallback_steps", "coupling_iterations", "most_in_a_step", "wall_s",
           "command"]
WELL = ["well.injector.position=[0.0, 0.0]", 'well.injector.fault="fault"', "fault.fault.pore_pressure_load=false",
        'fault.fault.flow="conduit"', "fault.fault.residual_aperture=1.0e-4", "coupling.tolerance=1e-10",
        "coupling.max_iterations=400"]
REACTIVATION, INJECTION3D = "scenes/fault_reactivation.toml", "scenes/injection_fault3d.toml"
CASES = {
    "1e-3": (REACTIVATION, WELL + ["well.injector.rate=1.0e-3", "time.end=345600.0"]),
    "1e-3-doubled": (REACTIVATION, WELL + ["well.injector.rate=1.0e-3", "time.end=345600.0", "mesh.size_factor=2.0"]),
    "5e-4": (REACTIVATION, WELL + ["well.injector.rate=5.0e-4", "time.end=864000.0"]),
    "5e-4-6h": (REACTIVATION, WELL + ["well.injector.rate=5.0e-4", "time.end=604800.0", "time.dt=21600.0"]),
    "5e-4-anderson": (REACTIVATION, WELL + ["well.injector.rate=5.0e-4", "time.end=864000.0",
                                            "coupling.acceleration=anderson"]),
    "5e-4-22.5min": (REACTIVATION, WELL + ["well.injector.rate=5.0e-4", "time.end=864000.0", "time.dt=1350.0"]),
    "5e-4-22.5min-retry": (REACTIVATION, WELL + ["well.injector.rate=5.0e-4", "time.end=864000.0", "time.dt=1350.0",
                                                 "time.retry=4"]),
    "5e-4-22.5min-fallback": (REACTIVATION, WELL + ["well.injector.rate=5.0e-4", "time.end=864000.0",
                                                    "time.dt=1350.0", 'coupling.fallback="monolithic"']),
    "5e-4-22.5min-multirate": (REACTIVATION, WELL + ["well.injector.rate=5.0e-4", "time.end=864000.0",
                                                     "time.dt=1350.0", 'coupling.scheme="multirate"', "coupling.q=2"]),
    "5e-4-22.5min-multirate-fallback": (REACTIVATION, WELL + ["well.injector.rate=5.0e-4", "time.end=864000.0",
                                                              "time.dt=1350.0", 'coupling.scheme="multirate"',
                                                              "coupling.q=2", 'coupling.fallback="monolithic"']),
    "5e-4-11.25min-multirate": (REACTIVATION, WELL + ["well.injector.rate=5.0e-4", "time.end=864000.0",
                                                      "time.dt=675.0", 'coupling.scheme="multirate"', "coupling.q=2"]),
    "5e-4-3h-bdf2": (REACTIVATION, WELL + ["well.injector.rate=5.0e-4", "time.end=864000.0", "time.dt=10800.0",
                                           'time.scheme="bdf2"']),
    "5e-4-3h-bdf2-retry": (REACTIVATION, WELL + ["well.injector.rate=5.0e-4", "time.end=864000.0",
                                                 "time.dt=10800.0", 'time.scheme="bdf2"', "time.retry=4"]),
    "3d-0.5": (INJECTION3D, ["well.injector.rate=0.5", "time.end=3600.0", "coupling.tolerance=1e-10"]),
    "3d-1.0": (INJECTION3D, ["well.injector.rate=1.0"]),
}


def one_run(binary, case, petsc, out):
    """A CSV row of one run, failed or not."""
    path, sets = CASES[case]
    try:
        command = common.run_case([binary], os.path.join(common.ROOT, path), sets + ["output.xdmf=false"], petsc,
                                  out)["command"]
    except common.BenchError as e:
        command = str(e)
    per_step = {}
    with open(os.path.join(out, "iterations.csv")) as f:
        for r in csv.DictReader(f):
            if int(r["step"]) > 0:
                per_step[r["step"]] = int(r["iteration"])
    with open(os.path.join(out, "summary.json")) as f:
        s = json.load(f)
    return {"case": case, "status": s["status"], "steps": s["steps"], "retries": s.get("retries", 0),
            "fallback_steps": s.get("fallback_steps", 0),
            "coupling_iterations": s["coupling_iterations"],
            "most_in_a_step": max(per_step.values(), default=0), "wall_s": s["wall_time_s"], "command": command}


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    common.add_arguments(p, NAME)
    p.add_argument("--cases", default=",".join(CASES), help=f"comma-separated subset of {','.join(CASES)}")
    args, petsc = common.parse_arguments(p)
    cases = [c.strip() for c in args.cases.split(",") if c.strip()]
    if not cases or any(c not in CASES for c in cases):
        raise common.BenchError(f"--cases: choose from {', '.join(CASES)}")
    recorder = common.start_recorder(args, petsc, NAME, COLUMNS, "fault_reactivation and injection_fault3d")
    with common.WorkDir(args.work_dir, args.keep_runs) as work:
        for case in cases:
            for repetition in range(1, args.repeat + 1):
                row = one_run(args.binary, case, petsc, work.run(f"{case}-r{repetition}"))
                recorder.add(dict(row, repetition=repetition))
    recorder.finish()
    report(recorder.rows, cases)
    return 0


def report(rows, cases):
    """One row per case: the first run's counts, the median wall time."""
    lines = []
    for case in cases:
        runs = [r for r in rows if r["case"] == case]
        r = runs[0]
        wall = statistics.median(float(x["wall_s"]) for x in runs)
        lines.append([case, r["status"], r["steps"], r["retries"], r.get("fallback_steps", 0),
                      r["coupling_iterations"], r["most_in_a_step"], f"{wall:.2f}"])
    print("\n".join(markdown.table(["case", "status", "steps", "retries", "fallback steps", "coupling iterations",
                                    "most in a step", "wall (s, median)"], lines)))

if __name__ == "__main__":
    sys.exit(common.main_wrapper(main))
