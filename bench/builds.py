#!/usr/bin/python3
"""Two builds on shipped scenes: whether a change slows the scenes that do
not use it. Each scene is run by the build before (`--before`) and the
build after (`--binary`), alternating, `--repeat` times; the wall time is
summary.json's `wall_time_s`.

Writes bench/results/builds.csv, one row per run, and prints per scene the
runs, the medians and their ratio (after / before) as a Markdown table.
"""
import argparse
import os
import statistics
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import common  # noqa: E402

NAME = "builds"
COLUMNS = ["scene", "build", "repetition", "wall_s", "process_wall_s", "coupling_iterations", "command"]
SCENES = "default,fault_reactivation,phan,sneddon,conduit_transient,fault_depletion"


def report(rows, scenes):
    """The Markdown table: per scene the runs of each build, their medians
    and the ratio after / before."""
    print("| scene | before | after | median before | median after | ratio |")
    print("| --- | --- | --- | --- | --- | --- |")
    for scene in scenes:
        runs = {b: [r["wall_s"] for r in rows if r["scene"] == scene and r["build"] == b] for b in ("before", "after")}
        before, after = statistics.median(runs["before"]), statistics.median(runs["after"])
        print(f"| {scene} | {', '.join('%.3f' % w for w in runs['before'])} | "
              f"{', '.join('%.3f' % w for w in runs['after'])} | {before:.3f} | {after:.3f} | {after / before:.3f} |")


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    common.add_arguments(p, NAME)
    p.add_argument("--before", required=True, help="the build before the change (a biotcontact binary)")
    p.add_argument("--scenes", default=SCENES, help=f"shipped scenes, comma-separated (default {SCENES})")
    args, petsc = common.parse_arguments(p)
    if not os.access(args.before, os.X_OK):
        raise common.BenchError(f"--before {args.before}: not an executable")
    scenes = [s.strip() for s in args.scenes.split(",") if s.strip()]
    header = common.machine_header(args.binary)
    header["before"] = os.path.abspath(args.before)
    header["fixed_sets"] = " ".join(args.sets)
    header["petsc_options"] = " ".join(petsc)
    common.print_header(header)
    recorder = common.Recorder(args.out_dir, NAME, COLUMNS, header, args.update)
    builds = {"before": os.path.abspath(args.before), "after": args.binary}
    with common.WorkDir(args.work_dir, args.keep_runs) as work:
        for scene in scenes:
            path = os.path.join(common.ROOT, "scenes", scene + ".toml")
            for repetition in range(1, args.repeat + 1):
                for build, binary in builds.items():
                    out = work.run(f"{scene}-{build}-r{repetition}")
                    result = common.run_case([binary], path, args.sets, petsc, out)
                    s = result["summary"]
                    recorder.add({"scene": scene, "build": build, "repetition": repetition, "wall_s": s["wall_time_s"],
                                  "process_wall_s": result["process_wall_s"],
                                  "coupling_iterations": s.get("coupling_iterations"), "command": result["command"]})
    recorder.finish()
    report(recorder.rows, scenes)
    return 0


if __name__ == "__main__":
    sys.exit(common.main_wrapper(main))
