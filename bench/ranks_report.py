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
        out.append([f"{one['dimension']}D", one["variant"], one["cells"], fmt(one["unknowns"]),
                    solvers.get(key(one), ""), solvers.get(key(two), ""), fmt(one["wall_s"]), fmt(two["wall_s"]),
                    f"{one['wall_s'] / two['wall_s']:.2f}", f"{one['process_wall_s'] / two['process_wall_s']:.2f}",
                    "yes" if same else f"no ({fmt(one['coupling_iterations'])} / {fmt(two['coupling_iterations'])})"])
    return out


def phase_rows(es):
    """Per phase, 1 and 2 ranks, for the single-rate 2D runs and the 3D
    block at three sizes each (the largest three run on both)."""
    out = []
    for dimension, variant in ((2, "paper"), (2, "monolithic"), (3, "auto")):
        cases = [p for p in pairs(es) if p[0]["dimension"] == dimension and p[0]["variant"] == variant][-3:]
        for one, two in cases:
            a, b = phases(one), phases(two)
            iterations = max(one["coupling_iterations"], one["steps"] if variant == "monolithic" else 0, 1)
            out.append([f"{dimension}D {variant}", one["cells"], fmt(one["unknowns"]), fmt(iterations)]
                       + [f"{fmt(a[p])} / {fmt(b[p])}" for p in PHASES])
    return out


def model(es):
    """Per phase of the largest 3D case: t(P) = s + p / P (+ reductions),
    s and p from the 1- and 2-rank times (Amdahl per phase: p = 2 (t1 - t2),
    clamped to [0, t1]). Strong scaling of that case, and weak scaling with
    its unknowns per rank on 2 ranks, where the parallel part stays per rank
    and the serial part grows with the problem as the measured sizes show."""
    cases = [p for p in pairs(es) if p[0]["dimension"] == 3]
    if len(cases) < 2:
        return None
    (small1, small2), (one, two) = cases[-2], cases[-1]
    growth = one["unknowns"] / small1["unknowns"]
    fits = {}
    for phase in PHASES:
        t1, t2 = phases(one)[phase], phases(two)[phase]
        p = min(max(2 * (t1 - t2), 0.0), t1)
        s = t1 - p
        # The serial part's growth with the problem, from the next smaller size.
        s_small = phases(small1)[phase] - min(max(2 * (phases(small1)[phase] - phases(small2)[phase]), 0.0),
                                              phases(small1)[phase])
        exponent = math.log(max(s, 1e-9) / max(s_small, 1e-9)) / math.log(growth) if s > 0 and s_small > 0 else 1.0
        fits[phase] = (s, p, min(max(exponent, 0.0), 2.0))
    # Global reductions per run: two per CG iteration and about twelve per
    # GMRES iteration (restart 30, growing Gram-Schmidt) of the Krylov solves.
    reductions = 2 * one["mechanics_linear_iterations"] + 12 * one["flow_linear_iterations"]
    return one, two, fits, reductions


def predict(fits, reductions, ranks, scale):
    """Seconds per phase on `ranks` for `scale` times the case's unknowns
    (strong: 1, weak: ranks / 2)."""
    t = {phase: s * scale ** exponent + p * scale * 1.0 / ranks for phase, (s, p, exponent) in fits.items()}
    t["global reductions"] = reductions * REDUCTION_LATENCY_S * math.log2(ranks)
    return t


def model_lines(es):
    fitted = model(es)
    if fitted is None:
        return ["_The model needs two 3D sizes on 1 and 2 ranks._", ""]
    one, two, fits, reductions = fitted
    lines = [f"Fitted on the 3D block at {one['cells']} ({fmt(one['unknowns'])} unknowns, the iterative path): "
             "per phase, the part that halved on 2 ranks (parallel, p) and the rest (serial, s, with its growth "
             "exponent in the unknowns from the next smaller size); global reductions "
             f"({fmt(reductions)} per run, from the Krylov iterations) cost an assumed "
             f"{REDUCTION_LATENCY_S * 1e6:.0f} us per tree level. Strong: the same problem; weak: "
             f"{fmt(one['unknowns'] / 2)} unknowns per rank, as on 2 ranks.", ""]
    header = ["phase", "s (s)", "p (s)", "s grows as N^"] + [f"strong {n}" for n in MODEL_RANKS] \
        + [f"weak {n}" for n in MODEL_RANKS]
    strong = {n: predict(fits, reductions, n, 1.0) for n in MODEL_RANKS}
    weak = {n: predict(fits, reductions, n, n / 2) for n in MODEL_RANKS}
    rows = [[phase, fmt(s), fmt(p), f"{exponent:.2f}"] + [fmt(strong[n][phase]) for n in MODEL_RANKS]
            + [fmt(weak[n][phase]) for n in MODEL_RANKS] for phase, (s, p, exponent) in fits.items()]
    rows.append(["global reductions", "-", "-", "-"] + [fmt(strong[n]["global reductions"]) for n in MODEL_RANKS]
                + [fmt(weak[n]["global reductions"]) for n in MODEL_RANKS])
    rows.append(["**total**", fmt(sum(f[0] for f in fits.values())), fmt(sum(f[1] for f in fits.values())), "-"]
                + [f"**{fmt(sum(strong[n].values()))}**" for n in MODEL_RANKS]
                + [f"**{fmt(sum(weak[n].values()))}**" for n in MODEL_RANKS])
    lines += table(header, rows)
    return lines + ["", f"Measured: {fmt(one['wall_s'])} s on 1 rank, {fmt(two['wall_s'])} s on 2 "
                    f"(model: {fmt(sum(predict(fits, reductions, 2, 1.0).values()))} s).", ""]


def targets(es):
    """The issue-24 targets."""
    speedups = [(one["wall_s"] / two["wall_s"], one, two) for one, two in pairs(es)]
    rows = []
    if speedups:
        worst = min(speedups, key=lambda x: x[0])
        rows.append(["2 ranks never slower than 1 (defaults, every case)", ">= 1.0x", "0.23x (2D [160,16])",
                     f"worst {worst[0]:.2f}x ({worst[1]['dimension']}D {worst[1]['variant']} {worst[1]['cells']})",
                     status(1.0 / worst[0], 1.0)])
    for label, dimension, variant, cells, goal in (("2D [640,64] single rate", 2, "paper", "[640,64]", 1.4),
                                                   ("3D block at 1.0e6 unknowns", 3, "auto", "[72,36,18]", 1.85)):
        found = [x for x in speedups if x[1]["dimension"] == dimension and x[1]["variant"] == variant
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
    families = dict.fromkeys((one["dimension"], one["variant"]) for one, _ in pairs(es))
    for marker, (dimension, variant) in zip("osD^v", families):
        runs = [(one["unknowns"], one["wall_s"] / two["wall_s"]) for one, two in pairs(es)
                if one["dimension"] == dimension and one["variant"] == variant]
        ax.semilogx([u for u, _ in runs], [s for _, s in runs], marker + "-",
                    label=f"{dimension}D {'block, defaults' if dimension == 3 else variant}")
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
    lines += ["Every case of the size sweep (2D, `scenes/default.toml`, to `time.end` 2.4) and of the 3D "
              "scaling (`scenes/block3d_box.toml`, two steps), with `auto` choosing each system's solver as a "
              "user's run does; the runs of a case alternate 1 and 2 ranks. Solvers: direct (d) or iterative (i) "
              "per system as `auto` chose them (flow/mechanics, or the monolithic system). Speed-up is the "
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
