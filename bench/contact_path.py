#!/usr/bin/python3
"""Is `auto`'s contact path the faster one? Each case on the condensed path
(`-<prefix>contact_condensed true`), the full one (`false`) and the default:
Sneddon's pressurised crack (scenes/sneddon.toml, one solve) at three
refinements, and the shipped fault and foundation scenes and the default
scene (many solves).

Writes bench/results/contact_path.csv, one row per run, and prints per case
the medians and the default's ratio to the faster path (issue 50: at most
1.2).
"""
import argparse
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import common  # noqa: E402

NAME = "contact_path"
# case: (scene, --set values)
CASES = {"sneddon0": ("scenes/sneddon.toml", ["mesh.refine=0"]),
         "sneddon1": ("scenes/sneddon.toml", ["mesh.refine=1"]),
         "sneddon2": ("scenes/sneddon.toml", ["mesh.refine=2"]),
         "fault_reactivation": ("scenes/fault_reactivation.toml", []),
         "fault_depletion": ("scenes/fault_depletion.toml", []),
         "injection_fault3d": ("scenes/injection_fault3d.toml", []),
         "fault3d": ("scenes/fault3d.toml", []), "fracture": ("scenes/fracture.toml", []),
         "hertz": ("scenes/hertz.toml", []), "default": ("scenes/default.toml", [])}
PATHS = {"condensed": ["-mechanics_contact_condensed", "true"], "full": ["-mechanics_contact_condensed", "false"],
         "default": []}
COLUMNS = ["case", "path", "repetition", "wall_s", "process_wall_s", "unknowns", "method", "solves",
           "factorizations", "schur_factorizations", "active_set_changes", "newton_iterations", "mechanics_s",
           "schur_s", "command"]


def row_of(case, path, repetition, result):
    s = result["summary"]
    m, t = s["solvers"]["mechanics"], s["timings"]["mechanics"]
    return {"case": case, "path": path, "repetition": repetition, "wall_s": float(s["wall_time_s"]),
            "process_wall_s": result["process_wall_s"], "unknowns": sum(s["dofs"].values()),
            "method": m["method"], "solves": m["solves"], "factorizations": m["factorizations"],
            "schur_factorizations": m.get("schur_factorizations", 0),
            "active_set_changes": m["active_set_changes"], "newton_iterations": m["newton_iterations"],
            "mechanics_s": t["total"], "schur_s": t["schur_complement"], "command": result["command"]}


def report(rows, cases):
    for case in cases:
        m = {path: common.medians([r for r in rows if r["case"] == case and r["path"] == path], [],
                                  ["wall_s"])[0]["wall_s"] for path in PATHS}
        faster = min(m["condensed"], m["full"])
        print(f"{case}: condensed {m['condensed']:.2f} s, full {m['full']:.2f} s, default {m['default']:.2f} s: "
              f"{m['default'] / faster:.2f}x the faster path")


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    common.add_arguments(p, NAME)
    p.add_argument("--cases", default=",".join(CASES), help=f"comma-separated subset of {','.join(CASES)}")
    args, petsc = common.parse_arguments(p)
    cases = common.parse_variants(args.cases, CASES)
    header = common.machine_header(args.binary)
    header["scene"] = "scenes/sneddon.toml at mesh.refine 0-2 and the shipped contact scenes"
    header["petsc_options"] = " ".join(petsc)
    common.print_header(header)
    recorder = common.Recorder(args.out_dir, NAME, COLUMNS, header, args.update)
    with common.WorkDir(args.work_dir, args.keep_runs) as work:
        for case in cases:
            for repetition in range(1, args.repeat + 1):
                for path, options in PATHS.items():
                    out = work.run(f"{case}-{path}-r{repetition}")
                    result = common.run_case([args.binary], os.path.join(common.ROOT, CASES[case][0]),
                                             args.sets + CASES[case][1], petsc + options, out)
                    row = row_of(case, path, repetition, result)
                    recorder.add(row)
                    print(f"  {case} {path} #{repetition}: {row['wall_s']:.2f} s ({row['method']})", flush=True)
    recorder.finish()
    report(recorder.rows, cases)
    return 0


if __name__ == "__main__":
    sys.exit(common.main_wrapper(main))
