"""The scaling section of docs/performance.md (bench/scaling.py's CSV):
tables of medians, the plot of time per unknown per coupling iteration, the
issue-10 targets and the crossover that `auto` uses (cpp/solvers/solver.h)."""
import os
import re

import common
from markdown import commands, fmt, provenance, status, table

FIELDS = ["unknowns", "flow_unknowns", "mechanics_unknowns", "wall_s", "coupling_iterations", "time_per_iteration_ms",
          "us_per_unknown_per_iteration", "flow_iterations_per_solve", "mechanics_iterations_per_newton_step",
          "flow_setups", "mechanics_setups", "active_set_changes", "flow_total_s", "mechanics_total_s",
          "flow_setup_s", "mechanics_setup_s", "peak_rss_mb", "kb_per_unknown"]
KEYS = ["dimension", "cells", "solver", "ranks"]
# cpp/solvers/solver.h: systems with at least this many unknowns are solved iteratively by "auto".
CROSSOVER_FILE = os.path.join(common.ROOT, "cpp", "solvers", "solver.h")


def entries(rows):
    """Medians per (dimension, cells, solver, ranks), sorted by size."""
    result = common.medians(rows, KEYS, FIELDS)
    return sorted(result, key=lambda e: (e["dimension"], e["unknowns"], e["solver"], int(e["ranks"])))


def crossovers():
    """{(dimension, system): unknowns} from cpp/solvers/solver.h."""
    with open(CROSSOVER_FILE) as f:
        text = f.read()
    return {(d, system): int(value) for d, system, value in re.findall(r"crossover_(\d)d_(mechanics|flow) = (\d+)", text)}


def _select(es, **match):
    return [e for e in es if all(str(e[k]) == str(v) for k, v in match.items())]


def iterations_target(es, dimension):
    """Linear iterations per solve, smallest to largest mesh, iterative, 1 rank."""
    runs = _select(es, dimension=dimension, solver="iterative", ranks=1)
    label = f"{dimension}D: linear iterations per solve, smallest to largest mesh"
    if len(runs) < 2:
        return [label, "<= 1.5x", "-", "not measured", "not measured"]
    parts, worst = [], 0.0
    for system, column in (("flow", "flow_iterations_per_solve"), ("mechanics", "mechanics_iterations_per_newton_step")):
        values = [e[column] for e in runs]
        ratio = max(values) / min(values)
        worst = max(worst, ratio)
        parts.append(f"{system} {min(values):.1f}-{max(values):.1f} ({ratio:.2f}x)")
    return [label, "<= 1.5x", "-", f"{'; '.join(parts)}; {runs[0]['cells']} to {runs[-1]['cells']}",
            status(worst, 1.5)]


def time_per_unknown_target(es):
    """2D iterative: time per unknown per iteration, from the first mesh with
    at least 1e5 unknowns to the largest."""
    runs = [e for e in _select(es, dimension=2, solver="iterative", ranks=1) if e["unknowns"] >= 1e5]
    label = "2D iterative: time per unknown per coupling iteration, 1e5 to 2e6 unknowns"
    if len(runs) < 2:
        return [label, "grows <= 1.3x", "-", "not measured", "not measured"]
    first, last = runs[0], runs[-1]
    ratio = last["us_per_unknown_per_iteration"] / first["us_per_unknown_per_iteration"]
    return [label, "grows <= 1.3x", "-",
            f"{first['us_per_unknown_per_iteration']:.3g} us at {fmt(first['unknowns'])} -> "
            f"{last['us_per_unknown_per_iteration']:.3g} us at {fmt(last['unknowns'])} ({ratio:.2f}x)",
            status(ratio, 1.3)]


def block_target(es):
    """3D block at about 1e6 unknowns, two steps, iterative, 1 rank."""
    runs = [e for e in _select(es, dimension=3, solver="iterative", ranks=1) if e["unknowns"] >= 9e5]
    label = "3D contact block, about 1e6 unknowns, two steps"
    goal = "<= 240 s and <= 6 GiB"
    if not runs:
        return [label, goal, "direct: ~600 s, 4.9 GB at 7.1e5", "not measured", "not measured"]
    e = runs[-1]
    ratio = max(e["wall_s"] / 240, e["peak_rss_mb"] / (6 * 1024))
    return [label, goal, "direct: ~600 s, 4.9 GB at 7.1e5",
            f"{e['wall_s']:.0f} s, {e['peak_rss_mb'] / 1024:.1f} GiB at {fmt(e['unknowns'])} ({e['cells']})",
            status(ratio, 1.0)]


def ranks_target(es):
    """2 ranks against 1, per solver on the largest 2D case run on both."""
    label = "2D, largest case on 2 ranks: speed-up over 1 rank"
    parts, speedups = [], {}
    for solver in ("iterative", "direct"):
        pairs = [(e, _select(es, dimension=2, ranks=1, cells=e["cells"], solver=solver))
                 for e in _select(es, dimension=2, ranks=2, solver=solver)]
        pairs = [(two, one[0]) for two, one in pairs if one]
        if not pairs:
            continue
        two, one = max(pairs, key=lambda p: p[0]["unknowns"])
        speedups[solver] = one["wall_s"] / two["wall_s"]
        parts.append(f"{solver} {two['cells']}: {one['wall_s']:.3g} s -> {two['wall_s']:.3g} s "
                     f"({speedups[solver]:.2f}x)")
    if not speedups:
        return [label, ">= 1.6x", "0.93x (direct, [160,16])", "not measured", "not measured"]
    best = max(speedups, key=speedups.get)
    verdict = ("met" if speedups[best] >= 1.6 else f"missed by {100 * (1.6 / speedups[best] - 1):.0f}%") \
        + f" ({best})"
    return [label, ">= 1.6x", "0.93x (direct, [160,16])", "; ".join(parts), verdict]


def auto_target(es):
    """Per system and size (1 rank): the faster method by the system's total
    time against the one `auto` picks from the crossovers in cpp/solvers/solver.h."""
    label = "`auto` picks the faster method per system (1 rank)"
    limits = crossovers()
    checked, wrong = 0, []
    for direct in _select(es, solver="direct", ranks=1):
        iterative = _select(es, solver="iterative", ranks=1, dimension=direct["dimension"], cells=direct["cells"])
        if not iterative:
            continue
        for system in ("flow", "mechanics"):
            times = {"direct": direct[f"{system}_total_s"], "iterative": iterative[0][f"{system}_total_s"]}
            limit = limits.get((str(direct["dimension"]), system))
            if limit is None:
                continue
            picked = "direct" if direct[f"{system}_unknowns"] < limit else "iterative"
            checked += 1
            if times[picked] > 1.2 * min(times.values()):
                wrong.append(f"{system} {direct['dimension']}D {direct['cells']}: {picked} "
                             f"{times[picked]:.3g} s against {min(times.values()):.3g} s")
    if not checked:
        return [label, "within 20%", "-", "not measured", "not measured"]
    if not wrong:
        return [label, "within 20%", "-", f"held in all {checked} comparisons", "met"]
    return [label, "within 20%", "-", f"{len(wrong)} of {checked} off: " + "; ".join(wrong), "missed"]


def targets(rows):
    es = entries(rows)
    return [iterations_target(es, 2), iterations_target(es, 3), time_per_unknown_target(es), block_target(es),
            ranks_target(es), auto_target(es)]


def plot(es, directory):
    """Time per unknown per coupling iteration against unknowns."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(7, 4.5))
    for key in dict.fromkeys((e["dimension"], e["solver"], e["ranks"]) for e in es):
        runs = _select(es, dimension=key[0], solver=key[1], ranks=key[2])
        ax.loglog([e["unknowns"] for e in runs], [e["us_per_unknown_per_iteration"] for e in runs],
                  "o-" if key[1] == "iterative" else "s--", label=f"{key[0]}D {key[1]}, {key[2]} rank(s)")
    ax.set_xlabel("unknowns")
    ax.set_ylabel("wall time per unknown per coupling iteration (us)")
    ax.set_title("Two time steps: direct against iterative")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    name = "scaling.png"
    fig.savefig(os.path.join(directory, name), dpi=110)
    plt.close(fig)
    return name


def section(header, rows, plot_dir, relative):
    es = entries(rows)
    lines = ["## Scaling: direct against iterative solvers", "", provenance(header), ""] + commands(header, rows)
    lines += ["2D: the default scene; 3D: `scenes/block3d_box.toml`; two time steps each (`time.end=0.4`), no "
              "XDMF output. `direct`/`iterative` set both `solver.flow` and `solver.mechanics`. Iterations per "
              "solve: flow GMRES iterations per solve, mechanics CG iterations per Newton step of the contact "
              "VI. Set-ups: factorisations (direct) or AMG hierarchies (iterative). Peak memory is the largest "
              f"process's. Medians over {max(e['repetitions'] for e in es)} repetition(s).", ""]
    lines += table(["dim", "cells", "solver", "ranks", "unknowns", "wall s", "coupling its", "ms / it",
                    "us / unknown / it", "its / solve (flow, mech)", "set-ups (flow, mech)", "flow s", "mech s",
                    "peak MB", "kB / unknown"],
                   [[e["dimension"], e["cells"], e["solver"], e["ranks"], fmt(e["unknowns"]), fmt(e["wall_s"]),
                     fmt(e["coupling_iterations"]), fmt(e["time_per_iteration_ms"]),
                     fmt(e["us_per_unknown_per_iteration"]),
                     f"{e['flow_iterations_per_solve']:.1f}, {e['mechanics_iterations_per_newton_step']:.1f}",
                     f"{fmt(e['flow_setups'])}, {fmt(e['mechanics_setups'])}", fmt(e["flow_total_s"]),
                     fmt(e["mechanics_total_s"]), fmt(e["peak_rss_mb"]), fmt(e["kb_per_unknown"])] for e in es])
    lines += ["", f"![time per unknown per iteration]({relative}/{plot(es, plot_dir)})", "",
              "Targets of issue 10 (bench, not ctest):", ""]
    lines += table(["target", "goal", "baseline", "measured (median)", "status"], targets(rows))
    return lines + [""]
