#!/usr/bin/python3
"""Runs the shipped coupled scenes with every scheme, q and L choice and
writes the table of iteration counts and contraction ratios against gamma
into docs/schemes.md, between its markers `<!-- scheme-table begin -->` and
`<!-- scheme-table end -->` (the rest of the page is hand-written and kept;
a page without the markers gets the block appended).

    /usr/bin/python3 tools/scheme_table.py [--binary build/biotcontact]
"""
import argparse
import datetime
import json
import os
import platform
import subprocess
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SCENES = [
    ("default", "scenes/default.toml", []),
    ("default, alpha = 0.8", "scenes/default.toml", ["coupling.alpha=0.8"]),
    ("default, M = 1e9", "scenes/default.toml", ["flow.M=1e9"]),
    ("terzaghi", "scenes/terzaghi.toml", []),
    ("fracture", "scenes/fracture.toml", []),
    ("caprock", "scenes/caprock.toml", []),
]
# (scheme, q, L, Anderson depth or 0 for the paper's iteration)
CASES = [
    ("fixed-stress", 1, "paper", 0), ("fixed-stress", 1, "kdr", 0), ("fixed-stress", 1, "half-kdr", 0),
    ("multirate", 2, "paper", 0), ("multirate", 4, "paper", 0), ("multirate", 8, "paper", 0),
    ("multirate", 16, "paper", 0), ("multirate", 4, "kdr", 0),
    ("fixed-stress", 1, "paper", 3), ("fixed-stress", 1, "paper", 8), ("fixed-stress", 1, "kdr", 8),
    ("multirate", 4, "paper", 8), ("multirate", 8, "paper", 8),
    ("multirate-two-pass", 4, "paper", 0), ("multirate-two-pass", 8, "paper", 0),
    ("multirate-two-pass", 16, "paper", 0), ("multirate-two-pass", 4, "kdr", 0),
    ("multirate-two-pass", 4, "paper", 8), ("multirate-two-pass", 8, "paper", 8),
    ("monolithic", 1, "paper", 0),
]
# The same with time.scheme = "bdf2" (docs/theory.md, "Time schemes").
BDF2_CASES = [
    ("fixed-stress", 1, "paper", 0), ("fixed-stress", 1, "kdr", 8), ("multirate", 4, "paper", 0),
    ("multirate-two-pass", 4, "paper", 0), ("multirate-two-pass", 4, "paper", 8), ("monolithic", 1, "paper", 0),
]
# BDF2 with time.adaptive (q = 1; docs/theory.md, "Adaptive steps") at one tolerance.
ADAPTIVE_TOLERANCE = 1e-3
ADAPTIVE_CASES = [("fixed-stress", 1, "paper", 0), ("fixed-stress", 1, "kdr", 8), ("monolithic", 1, "paper", 0)]
# coupling.q = "auto" (docs/theory.md, "Multirate with q = auto"): each window's q
# its own, Theorem 2's quantity measured with it.
AUTO_CASES = [("multirate", "auto", "paper", 0), ("multirate-two-pass", "auto", "paper", 0)]
TIME_SETTINGS = {"BE": ["time.scheme=backward-euler"], "BDF2": ["time.scheme=bdf2"],
                 f"BDF2, adaptive {ADAPTIVE_TOLERANCE:g}": ["time.scheme=bdf2",
                                                           f"time.adaptive.tolerance={ADAPTIVE_TOLERANCE}"]}


def run(binary, scene, overrides):
    out = tempfile.mkdtemp(prefix="scheme-table-")
    cmd = [binary, "run", os.path.join(ROOT, scene), "--out", out, "--set", "output.xdmf=false",
           "--set", "coupling.max_iterations=3000"]
    for o in overrides:
        cmd += ["--set", o]
    p = subprocess.run(cmd, capture_output=True, text=True)
    if not os.path.exists(os.path.join(out, "summary.json")):
        return None, p.stderr.strip().split(": ")[-1]
    with open(os.path.join(out, "summary.json")) as f:
        return json.load(f), p.returncode


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--binary", default=os.path.join(ROOT, "build", "biotcontact"))
    args = parser.parse_args()
    rows = ["| scene | scheme | time | q | L | acceleration | gamma | mechanics steps | coupling iterations "
            "(max/step) | per mechanics step | mechanics solves | flow solves | max ratio (mean) | ratios > gamma "
            "| wall s |",
            "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    labels = list(TIME_SETTINGS)
    cases = ([c + (labels[0],) for c in CASES] + [c + (labels[1],) for c in BDF2_CASES]
             + [c + (labels[2],) for c in ADAPTIVE_CASES] + [c + (labels[0],) for c in AUTO_CASES])
    for label, scene, overrides in SCENES:
        for scheme, q, L, depth, time_label in cases:
            accelerate = ["coupling.acceleration=anderson", f"coupling.depth={depth}"] if depth else []
            s, code = run(args.binary, scene, overrides + [f"coupling.scheme={scheme}", f"coupling.q={q}",
                                                            f"coupling.L={L}"] + TIME_SETTINGS[time_label]
                          + accelerate)
            acceleration = f"Anderson ({depth})" if depth else "-"
            if s is None:
                rows.append(f"| {label} | {scheme} | {time_label} | {q} | {L} | {acceleration} | not run: {code} "
                            "||||||||| ")
                continue
            steps = f"{s['steps']}" + (f" ({s['adaptive']['rejected_steps']} rejected)" if "adaptive" in s else "")
            if "window_steps" in s:
                q = f"auto (mean {s['window_steps']['mean_q']:.1f}, largest {s['window_steps']['largest_q']})"
            if scheme == "monolithic":
                work = f"| {steps} | - | - | {s['monolithic_solves']} coupled | - | - | - "
                L = "-"
            else:
                conv = "" if s["converged"] else " (not converged)"
                # accelerated iterates are not the map's: no ratio is held against gamma
                ratios = ("| - | - " if depth else
                          f"| {s['max_contraction_ratio']:.3f} ({s['mean_contraction_ratio']:.3f}) "
                          f"| {s['bound_violations']} of {s['resolved_ratios']} ")
                per_step = s["coupling_iterations"] / s["steps"] if s["steps"] else float("nan")
                work = (f"| {steps} | {s['coupling_iterations']} ({s['max_iterations_per_step']}){conv} "
                        f"| {per_step:.1f} | {s['mechanics_solves']} | {s['flow_solves']} {ratios}")
            rows.append(f"| {label} | {scheme} | {time_label} | {q} | {L} | {acceleration} | {s['gamma']:.3f} {work}"
                        f"| {s['wall_time_s']:.1f} |")
            print(rows[-1], flush=True)
    stamp = (f"Generated by `/usr/bin/python3 tools/scheme_table.py` on {platform.node()} "
             f"({os.cpu_count()} cores), {datetime.date.today()}. Ratios are Theorem 1's quantity "
             "for fixed-stress and Theorem 2's for both multirate schemes (for the two-pass variant no "
             "theorem bounds it by gamma: it is measured); only resolved ratios are counted "
             "(see [the theorems' quantities](theory.md#the-theorems-quantities-as-measured)). "
             "Two-pass: coupling.scheme = \"multirate-two-pass\", 2q flow solves per iteration. "
             "L = paper is alpha^2/lambda, the theorems' choice. Anderson (m): "
             "coupling.acceleration = \"anderson\" with depth m; its iterates are not the paper's map, so no "
             "ratio is held against gamma. Time: BE backward Euler, BDF2 time.scheme = \"bdf2\" (with the "
             "quadratic displacement path in the multirate windows: outside Theorem 2); BDF2, adaptive: "
             f"time.adaptive.tolerance = {ADAPTIVE_TOLERANCE:g}, steps chosen by the error estimate from the "
             "scene's dt as the first (rejected steps counted in the mechanics steps' column). q = auto: "
             "coupling.q = \"auto\" with its defaults (q_max 16, q_tolerance 1e-2), each window's own q.")
    table = stamp + "\n\n" + "\n".join(rows) + "\n"
    write_block(os.path.join(ROOT, "docs", "schemes.md"), table)


def write_block(path, table):
    """Replaces the text between the scheme-table markers of `path` by
    `table`, keeping the rest; appends the block if a marker is missing."""
    begin, end = "<!-- scheme-table begin -->", "<!-- scheme-table end -->"
    text = ""
    if os.path.exists(path):
        with open(path) as f:
            text = f.read()
    block = begin + "\n" + table + end
    if begin in text and end in text.split(begin, 1)[1]:
        head, rest = text.split(begin, 1)
        text = head + block + rest.split(end, 1)[1]
    else:
        text = (text.rstrip("\n") + "\n\n" if text else "# Schemes, q and L on the shipped scenes\n\n") + block + "\n"
    with open(path, "w") as f:
        f.write(text)
    print(f"wrote the scheme table into {os.path.relpath(path, ROOT)}")


if __name__ == "__main__":
    main()
