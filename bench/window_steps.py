#!/usr/bin/python3
"""What coupling.q = "auto" costs and saves on the fracture scene: single
rate, multirate with q = "auto" and with a fixed q = 16, backward Euler, at
the fracture study's three levels (mesh.refine 0, 1, 2 with dt 1 day,
12 h, 6 h), runs of the three variants interleaved.

q = "auto" takes the single-rate pressure error (tests/test_window_steps.py,
docs/studies/fracture); q = 16 the smallest wall time. Writes
bench/results/window_steps.csv, one row per run and repetition, and prints
the median wall time of each variant and level with its ratio to single
rate. No XDMF output (output.xdmf=false).
"""
import argparse
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import common  # noqa: E402

NAME = "window_steps"
SCENE = os.path.join(common.ROOT, "scenes", "fracture.toml")
LEVELS = {"0": ["mesh.refine=0", "time.dt=86400"], "1": ["mesh.refine=1", "time.dt=43200"],
          "2": ["mesh.refine=2", "time.dt=21600"]}
VARIANTS = {"single": ["coupling.scheme=fixed-stress"],
            "auto": ["coupling.scheme=multirate", "coupling.q=auto"],
            "q16": ["coupling.scheme=multirate", "coupling.q=16"]}
COLUMNS = ["level", "variant", "repetition", "wall_s", "process_wall_s", "unknowns", "steps", "fine_steps",
           "coupling_iterations", "flow_solves", "mechanics_solves", "mean_q", "q_rejections", "flow_s",
           "mechanics_s", "assembly_s", "command"]


def row(level, variant, repetition, result):
    """The CSV row of one run."""
    s = result["summary"]
    timings, windows = s["timings"], s.get("window_steps", {})
    return {"level": level, "variant": variant, "repetition": repetition, "wall_s": float(s["wall_time_s"]),
            "process_wall_s": result["process_wall_s"], "unknowns": sum(s["dofs"].values()), "steps": s["steps"],
            "fine_steps": s["fine_steps"], "coupling_iterations": s["coupling_iterations"],
            "flow_solves": s["flow_solves"], "mechanics_solves": s["mechanics_solves"],
            "mean_q": windows.get("mean_q", s["fine_steps"] / max(1, s["steps"])),
            "q_rejections": windows.get("q_rejections", 0), "flow_s": timings["flow"]["total"],
            "mechanics_s": timings["mechanics"]["total"], "assembly_s": timings["assembly"],
            "command": result["command"]}


def summarise(rows, levels):
    """Prints the medians of each level and variant, and their ratio to single rate."""
    fields = ["wall_s", "mechanics_solves", "flow_solves", "mean_q", "q_rejections"]
    for level in levels:
        entries = {e["variant"]: e for e in common.medians([r for r in rows if r["level"] == level],
                                                            ["variant"], fields)}
        single = entries["single"]["wall_s"]
        for variant, e in entries.items():
            print(f"level {level} {variant:6s}: wall {e['wall_s']:.2f} s (x{e['wall_s'] / single:.2f}), "
                  f"mechanics solves {e['mechanics_solves']:.0f}, flow solves {e['flow_solves']:.0f}, "
                  f"mean q {e['mean_q']:.2f}, {e['q_rejections']:.0f} windows again with q = 1")


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    common.add_arguments(p, NAME)
    p.add_argument("--levels", default=",".join(LEVELS), help=f"comma-separated subset of {','.join(LEVELS)}")
    args, petsc = common.parse_arguments(p)
    levels = common.parse_variants(args.levels, LEVELS)
    header = common.machine_header(args.binary)
    header["scene"] = "scenes/fracture.toml, output.xdmf=false"
    header["fixed_sets"] = " ".join(args.sets)
    header["petsc_options"] = " ".join(petsc)
    common.print_header(header)
    recorder = common.Recorder(args.out_dir, NAME, COLUMNS, header, args.update)
    with common.WorkDir(args.work_dir, args.keep_runs) as work:
        for level in levels:
            for repetition in range(1, args.repeat + 1):
                for variant, sets in VARIANTS.items():  # interleaved: the machine's drift hits all alike
                    out = work.run(f"{level}-{variant}-r{repetition}")
                    result = common.run_case([args.binary], SCENE, LEVELS[level] + sets + ["output.xdmf=false"]
                                             + args.sets, petsc, out)
                    recorder.add(row(level, variant, repetition, result))
    recorder.finish()
    summarise(recorder.rows, levels)
    return 0


if __name__ == "__main__":
    sys.exit(common.main_wrapper(main))
