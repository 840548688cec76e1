"""The "More ranks" section of docs/performance.md (bench/ranks.py's CSV):
the speed-up of 2 ranks over 1 for every case, where the time goes on each,
the issue-24 targets, and a per-phase model that extrapolates the 3D block
to 8, 64 and 512 ranks."""
import math
import os

import common
from markdown import commands, fmt, provenance, status, table

SYSTEMS = ("flow", "mechanics", "monolithic")
FIELDS = (["unknowns", "wall_s", "process_wall_s", "coupling_iterations", "steps", "assembly_s", "output_s",
           "mechanics_newton_iterations", "active_set_changes", "peak_rss_mb"]
          + [f"{s}_{p}_s" for s in SYSTEMS for p in ("setup", "solve", "schur_complement", "other", "total")]
          + [f"{s}_linear_iterations" for s in SYSTEMS])
KEYS = ["dimension", "variant", "cells", "ranks"]
# The phases of a run, from the summary's timings: each system's set-ups,
# back-solves or Krylov iterations, contact Schur complement and the rest of
# its solve (the contact VI's Newton steps on the condensed or full system),
# the assembly of loads and matrices, output, and what none of them covers
# (mesh, forms, the coupling's vector work, start-up).
PHASES = ("assembly", "set-ups", "solves", "Schur complement", "contact VI and rest of solve", "output", "other")
MODEL_RANKS = (8, 64, 512)
# An assumed, not measured, latency of one global reduction across nodes
# (a few microseconds per tree level on InfiniBand-class networks).
REDUCTION_LATENCY_S = 3e-6


def entries(rows):
    """Medians per (dimension, variant, cells, ranks), by size."""
    result = common.medians(rows, KEYS, FIELDS)
    return sorted(result, key=lambda e: (e["dimension"], e["variant"], e["unknowns"], int(e["ranks"])))


def family(e):
    """"2D", "3D", or "faults" (the shipped fault scenes, bench/ranks.py --dims faults)."""
    return "faults" if str(e["dimension"]) == "faults" else f"{e['dimension']}D"


def mesh(e):
    """The case's cells, "shipped" for a scene's own mesh."""
    return e["cells"] if e["cells"] != "[]" else "shipped"


def _select(es, **match):
    return [e for e in es if all(str(e[k]) == str(v) for k, v in match.items())]


def phases(e):
    """{phase: seconds} of one median entry."""
    systems = [s for s in SYSTEMS if e[f"{s}_total_s"] > 0]
    p = {"assembly": e["assembly_s"], "output": e["output_s"],
         "set-ups": sum(e[f"{s}_setup_s"] for s in systems),
         "solves": sum(e[f"{s}_solve_s"] for s in systems),
         "Schur complement": sum(e[f"{s}_schur_complement_s"] for s in systems),
         "contact VI and rest of solve": sum(e[f"{s}_other_s"] for s in systems)}
    p["other"] = max(e["wall_s"] - sum(p.values()), 0.0)
    return p


def pairs(es):
    """(one rank, two ranks) entries of every case run on both."""
    result = []
    for two in _select(es, ranks=2):
        one = _select(es, ranks=1, dimension=two["dimension"], variant=two["variant"], cells=two["cells"])
        if one:
            result.append((one[0], two))
    return result


def speedup_rows(es, rows):
    """The speed-up table, with the solvers auto chose and whether both rank
    counts made the same coupling iterations."""
    solvers = {}
    for r in rows:
        key = (str(r["dimension"]), r["variant"], r["cells"], str(r["ranks"]))
        solvers[key] = "/".join(r[f"{s}_solver"] for s in SYSTEMS if r[f"{s}_solver"])
    out = []
    for one, two in pairs(es):
        key = lambda e: (str(e["dimension"]), e["variant"], e["cells"], str(e["ranks"]))  # noqa: E731
        same = one["coupling_iterations"] == two["coupling_iterations"] and one["steps"] == two["steps"]
        out.append([family(one), one["variant"], mesh(one), fmt(one["unknowns"]),
                    solvers.get(key(one), ""), solvers.get(key(two), ""), fmt(one["wall_s"]), fmt(two["wall_s"]),
                    f"{one['wall_s'] / two['wall_s']:.2f}", f"{one['process_wall_s'] / two['process_wall_s']:.2f}",
                    "yes" if same else f"no ({fmt(one['coupling_iterations'])} / {fmt(two['coupling_iterations'])})"])
    return out


def phase_rows(es):
    """Per phase, 1 and 2 ranks, for the single-rate 2D runs and the 3D
    block at three sizes each (the largest three run on both)."""
    out = []
    for dimension, variant in ((2, "paper"), (2, "monolithic"), (3, "auto")):
        cases = [p for p in pairs(es) if str(p[0]["dimension"]) == str(dimension) and p[0]["variant"] == variant][-3:]
        for one, two in cases:
            a, b = phases(one), phases(two)
            iterations = max(one["coupling_iterations"], one["steps"] if variant == "monolithic" else 0, 1)
            out.append([f"{dimension}D {variant}", one["cells"], fmt(one["unknowns"]), fmt(iterations)]
                       + [f"{fmt(a[p])} / {fmt(b[p])}" for p in PHASES])
    return out


def model(es):
    """Per phase of the largest 3D case (the iterative path), from its 1- and
    2-rank times: the work w = t1, which divides by the ranks, and the
    overhead c = t2 - t1 / 2 of 2 ranks beyond halving it (communication and
    the memory bandwidth the ranks share), taken to grow with the depth of a
    reduction tree, log2 P, and with the surface of a rank's part,
    (N / P)^(2/3). The solves' work also grows with the Krylov iterations,
    measured from the next smaller size on one rank."""
    cases = [p for p in pairs(es) if str(p[0]["dimension"]) == "3"]
    if len(cases) < 2:
        return None
    small, (one, two) = cases[-2][0], cases[-1]
    its = lambda e: e["flow_linear_iterations"] + e["mechanics_linear_iterations"]  # noqa: E731
    growth = math.log(its(one) / its(small)) / math.log(one["unknowns"] / small["unknowns"])
    fits = {phase: (phases(one)[phase], max(phases(two)[phase] - phases(one)[phase] / 2, 0.0)) for phase in PHASES}
    # Global reductions per run: two per CG iteration and about twelve per
    # GMRES iteration (restart 30, growing Gram-Schmidt) of the Krylov solves.
    reductions = 2 * one["mechanics_linear_iterations"] + 12 * one["flow_linear_iterations"]
    return one, two, fits, reductions, growth


def predict(fits, reductions, growth, ranks, scale):
    """Seconds per phase on `ranks` for `scale` times the case's unknowns
    (strong: 1, weak: ranks / 2)."""
    surface = (2 * scale / ranks) ** (2 / 3)
    t = {}
    for phase, (work, overhead) in fits.items():
        iterations = scale ** growth if phase == "solves" else 1.0
        t[phase] = work * scale * iterations / ranks + overhead * math.log2(ranks) * surface
    t["global reductions"] = reductions * scale ** growth * REDUCTION_LATENCY_S * math.log2(ranks)
    return t


def model_lines(es):
    fitted = model(es)
    if fitted is None:
        return ["_The model needs two 3D sizes on 1 and 2 ranks._", ""]
    one, two, fits, reductions, growth = fitted
    lines = [f"Fitted on the 3D block at {one['cells']} ({fmt(one['unknowns'])} unknowns, the iterative path), "
             "per phase: the work w (the 1-rank time, divided by the ranks) and the overhead c of 2 ranks "
             "beyond halving it (t2 - t1/2: communication, and the memory bandwidth two ranks share), grown "
             "with log2 P and the surface (N/P)^(2/3) of a rank's part; the Krylov iterations grow as "
             f"N^{growth:.2f} (measured between the two largest sizes); global reductions "
             f"({fmt(reductions)} per run) cost an assumed {REDUCTION_LATENCY_S * 1e6:.0f} us per tree level "
             f"across nodes. Strong: the same problem; weak: {fmt(one['unknowns'] / 2)} unknowns per rank, "
             "as on 2 ranks. Seconds per run.", ""]
    header = ["phase", "w (s)", "c (s)"] + [f"strong {n}" for n in MODEL_RANKS] + [f"weak {n}" for n in MODEL_RANKS]
    strong = {n: predict(fits, reductions, growth, n, 1.0) for n in MODEL_RANKS}
    weak = {n: predict(fits, reductions, growth, n, n / 2) for n in MODEL_RANKS}
    rows = [[phase, fmt(w), fmt(c)] + [fmt(strong[n][phase]) for n in MODEL_RANKS]
            + [fmt(weak[n][phase]) for n in MODEL_RANKS] for phase, (w, c) in fits.items() if w > 0]
    rows.append(["global reductions", "-", "-"] + [fmt(strong[n]["global reductions"]) for n in MODEL_RANKS]
                + [fmt(weak[n]["global reductions"]) for n in MODEL_RANKS])
    rows.append(["**total**", fmt(sum(f[0] for f in fits.values())), fmt(sum(f[1] for f in fits.values()))]
                + [f"**{fmt(sum(strong[n].values()))}**" for n in MODEL_RANKS]
                + [f"**{fmt(sum(weak[n].values()))}**" for n in MODEL_RANKS])
    lines += table(header, rows)
    return lines + ["", f"Measured: {fmt(one['wall_s'])} s on 1 rank, {fmt(two['wall_s'])} s on 2 "
                    f"(the model: {fmt(sum(predict(fits, reductions, growth, 2, 1.0).values()))} s).", ""]


def targets(es):
    """The issue-24 targets."""
    speedups = [(one["wall_s"] / two["wall_s"], one, two) for one, two in pairs(es)]
    rows = []
    if speedups:
        worst = min(speedups, key=lambda x: x[0])
        rows.append(["2 ranks never slower than 1 (defaults, every case)", ">= 1.0x", "0.23x (2D [160,16])",
                     f"worst {worst[0]:.2f}x ({family(worst[1])} {worst[1]['variant']} {mesh(worst[1])})",
                     status(1.0 / worst[0], 1.0)])
    faults = [x for x in speedups if family(x[1]) == "faults"]
    if faults:
        worst = min(faults, key=lambda x: x[0])
        rows.append(["the shipped fault scenes: 2 ranks at least as fast as 1 (issue 51)", ">= 1.0x",
                     "0.18x (injection_fault3d, issue 51)", f"worst {worst[0]:.2f}x ({worst[1]['variant']}), "
                     f"{sum(x[0] >= 1.0 for x in faults)} of {len(faults)} at least 1.0x", status(1.0 / worst[0], 1.0)])
    for label, dimension, variant, cells, goal in (("2D [640,64] single rate", 2, "paper", "[640,64]", 1.4),
                                                   ("3D block at 1.0e6 unknowns", 3, "auto", "[72,36,18]", 1.85)):
        found = [x for x in speedups if str(x[1]["dimension"]) == str(dimension) and x[1]["variant"] == variant
                 and x[1]["cells"] == cells]
        measured = f"{found[0][0]:.2f}x ({fmt(found[0][1]['wall_s'])} s -> {fmt(found[0][2]['wall_s'])} s)" \
            if found else "not measured"
        rows.append([f"{label} on 2 ranks", f">= {goal}x", "-", measured,
                     status(goal / found[0][0], 1.0) if found else "not measured"])
    same = [x for x in speedups if x[1]["coupling_iterations"] == x[2]["coupling_iterations"]]
    rows.append(["same coupling iterations on 1 and 2 ranks", "every case", "-",
                 f"{len(same)} of {len(speedups)} cases", "met" if len(same) == len(speedups) else "missed"])
    return rows


def plot(es, directory):
    """Speed-up of 2 ranks over 1 against unknowns, per case family."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(7.5, 4.5))
    families = dict.fromkeys((one["dimension"], one["variant"]) for one, _ in pairs(es) if family(one) != "faults")
    for marker, (dimension, variant) in zip("osD^v", families):
        runs = [(one["unknowns"], one["wall_s"] / two["wall_s"]) for one, two in pairs(es)
                if str(one["dimension"]) == str(dimension) and one["variant"] == variant]
        ax.semilogx([u for u, _ in runs], [s for _, s in runs], marker + "-",
                    label={"paper": f"{dimension}D default scene, single rate", "monolithic":
                           f"{dimension}D default scene, monolithic"}.get(variant, f"{dimension}D block"))
    ax.axhline(1.0, color="black", lw=0.8)
    ax.axhline(2.0, color="grey", lw=0.8, ls=":")
    ax.set_xlabel("unknowns")
    ax.set_ylabel("speed-up, 2 ranks over 1 (wall time)")
    ax.set_title("2 ranks against 1, default solvers")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8, loc="center left", bbox_to_anchor=(1.01, 0.5))
    fig.tight_layout()
    name = "ranks.png"
    fig.savefig(os.path.join(directory, name), dpi=110)
    plt.close(fig)
    return name


def section(header, rows, plot_dir, relative):
    es = entries(rows)
    lines = ["## More ranks: 1 against 2 with the default solvers", "", provenance(header), ""]
    lines += commands(header, rows)
    lines += ["The meshes of the size sweep (2D, `scenes/default.toml`, 48 steps, single rate `paper` and "
              "`monolithic`) and of the 3D scaling (`scenes/block3d_box.toml`, two steps), with `auto` choosing "
              "each system's solver as a "
              "user's run does; the runs of a case alternate 1 and 2 ranks. Solvers: direct or iterative per "
              "system as `auto` chose them (flow/mechanics, or the monolithic system). Speed-up is the "
              "solver's wall time on 1 rank over that on 2; process adds start-up and exit. "
              f"Medians over {max(e['repetitions'] for e in es)} repetitions.", ""]
    lines += table(["dim", "variant", "cells", "unknowns", "solvers, 1 rank", "solvers, 2 ranks", "1 rank s",
                    "2 ranks s", "speed-up", "process speed-up", "same coupling iterations"],
                   speedup_rows(es, rows))
    lines += ["", f"![speed-up of 2 ranks]({relative}/{plot(es, plot_dir)})", "",
              "Where the time goes, 1 rank / 2 ranks (seconds per run; phases as in the summary's timings, "
              "'other' is the rest of the wall time: mesh, forms, the coupling's vector work):", ""]
    lines += table(["case", "cells", "unknowns", "iterations"] + list(PHASES), phase_rows(es))
    lines += ["", "### Extrapolation to a cluster (model)", ""] + model_lines(es)
    lines += ["Targets of issue 24 (bench, not ctest):", ""]
    lines += table(["target", "goal", "baseline", "measured (median)", "status"], targets(es))
    return lines + [""]


def auto_section(header, rows):
    """bench/auto.py: per shipped 3D scene and rank count, the wall time and
    coupling iterations of each solver choice, and whether `auto` is within
    10 % of the fastest."""
    es = common.medians(rows, ["scene", "variant", "ranks"], ["wall_s", "coupling_iterations", "unknowns"])
    picked = {}
    for r in rows:
        if r["variant"] == "auto":
            picked[(r["scene"], str(r["ranks"]))] = f"{r['flow_solver']}/{r['mechanics_solver']}"
    out, held = [], 0
    for scene, ranks in dict.fromkeys((e["scene"], str(e["ranks"])) for e in es):
        by = {e["variant"]: e for e in es if e["scene"] == scene and str(e["ranks"]) == ranks}
        if not {"direct", "iterative", "auto"} <= set(by):
            continue
        fastest = min(("direct", "iterative"), key=lambda c: by[c]["wall_s"])
        ok = by["auto"]["wall_s"] <= 1.1 * by[fastest]["wall_s"]
        held += ok
        out.append([scene, ranks, fmt(by["auto"]["unknowns"])]
                   + [f"{fmt(by[c]['wall_s'])} ({fmt(by[c]['coupling_iterations'])})"
                      for c in ("direct", "iterative", "auto")]
                   + [picked.get((scene, ranks), ""), fastest, "yes" if ok else "no"])
    lines = ["## Is `auto` right on the shipped 3D scenes?", "", provenance(header), ""] + commands(header, rows)
    lines += ["Both systems direct, both iterative, and `auto` (flow/mechanics as it chose them), on 1 and 2 "
              "ranks; wall time in s (coupling iterations). Medians over "
              f"{max(e['repetitions'] for e in es)} repetitions.", ""]
    lines += table(["scene", "ranks", "unknowns", "direct", "iterative", "auto", "auto chose", "fastest",
                    "auto within 10 %"], out)
    return lines + ["", f"`auto` within 10 % of the faster choice in {held} of {len(out)} cases.", ""]
