#!/usr/bin/python3
"""Two size sweeps side by side: the median wall time of each variant and
mesh in each, their ratio, and whether the coupling iterations agree. For a
change that must not slow the scenes that do not use it, sweep the binary
before and after into two directories, then compare:

    /usr/bin/python3 bench/size_sweep.py --binary OLD --out-dir /tmp/before ...
    /usr/bin/python3 bench/size_sweep.py --binary NEW --out-dir /tmp/after ...
    /usr/bin/python3 bench/compare_sweeps.py /tmp/before/size_sweep.csv /tmp/after/size_sweep.csv

Prints a Markdown table (ratio = after / before).
"""
import argparse
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import common  # noqa: E402

KEYS = ("variant", "cells")
FIELDS = ("wall_s", "coupling_iterations")


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("before", help="size_sweep.csv of the first binary")
    p.add_argument("after", help="size_sweep.csv of the second binary")
    args = p.parse_args(argv)
    tables = [{tuple(m[k] for k in KEYS): m for m in common.medians(common.read_csv(path)[1], KEYS, FIELDS)}
              for path in (args.before, args.after)]
    print("| variant | cells | before (s) | after (s) | ratio | iterations |")
    print("| --- | --- | --- | --- | --- | --- |")
    for key, before in tables[0].items():
        after = tables[1].get(key)
        if after is None:
            continue
        same = "same" if before["coupling_iterations"] == after["coupling_iterations"] else "differ"
        print(f"| {key[0]} | {key[1]} | {before['wall_s']:.2f} | {after['wall_s']:.2f} | "
              f"{after['wall_s'] / before['wall_s']:.3f} | {same} |")


if __name__ == "__main__":
    sys.exit(common.main_wrapper(main))
