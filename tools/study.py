#!/usr/bin/python3
"""Error against run time: sweeps a scene over schemes, q, L, dt and mesh
levels with the C++ solver, and writes results.csv, PNG plots and report.md.

    /usr/bin/python3 tools/study.py studies/contact.toml --out DIR [--binary build/biotcontact]

A study file names a scene, a list of levels (overrides that set h and dt
together) and a list of variants (overrides that choose scheme, q, L); every
variant runs on every level. Errors are measured against the closed form
(`reference = "closed-form"`, Terzaghi) or against a monolithic run on the
finest level (`reference = "monolithic"`, computed once and cached), at every
output time of the run: relative l2 errors of pressure (cell-area weighted),
displacement (nodal) and flux (cell-area weighted), at the final time and
the maximum over time. Finished runs are kept under DIR/runs and reused when
the study is started again.
"""
import argparse
import csv
import datetime
import hashlib
import json
import math
import os
import platform
import subprocess
import sys
import time
import tomllib

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, ROOT)
from python_prototype.diagnostics.closed_form import Terzaghi  # noqa: E402
from python_prototype.output.time_series import Fields  # noqa: E402

COLUMNS = ["variant", "scheme", "q", "L", "level", "h", "dt", "dofs", "steps", "coupling_iterations",
           "flow_solves", "mechanics_solves", "monolithic_solves", "wall_time_s", "time_flow_s",
           "time_mechanics_s", "time_monolithic_s", "time_assembly_s", "time_output_s",
           "pressure_error_final", "pressure_error_max", "displacement_error_final", "displacement_error_max",
           "flux_error_final", "flux_error_max", "gamma", "reference", "cached"]


class StudyError(Exception):
    pass


def read_study(path):
    try:
        with open(path, "rb") as f:
            study = tomllib.load(f)
    except FileNotFoundError:
        raise StudyError(f"{path}: study file not found")
    except tomllib.TOMLDecodeError as e:
        raise StudyError(f"{path}: invalid TOML: {e}")
    for key in ("name", "scene", "reference", "levels", "variants"):
        if key not in study:
            raise StudyError(f"{path}: {key}: missing")
    if study["reference"] not in ("closed-form", "monolithic"):
        raise StudyError(f"{path}: reference: must be \"closed-form\" or \"monolithic\"")
    return study


def run(binary, scene, overrides, directory):
    """Runs the solver into `directory` unless a finished run with the same
    command is there already; returns (summary, cached)."""
    command = [binary, "run", os.path.join(ROOT, scene), "--out", directory]
    for o in overrides:
        command += ["--set", o]
    stamp = os.path.join(directory, "command.json")
    summary = os.path.join(directory, "summary.json")
    if os.path.exists(stamp) and os.path.exists(summary):
        with open(stamp) as f:
            if json.load(f) == command[2:]:
                with open(summary) as g:
                    return json.load(g), True
    p = subprocess.run(command, capture_output=True, text=True)
    if not os.path.exists(summary):
        raise StudyError(f"run failed: {' '.join(command)}: {p.stderr.strip()}")
    with open(stamp, "w") as f:
        json.dump(command[2:], f)
    with open(summary) as f:
        return json.load(f), False


def run_directory(out, scene, overrides):
    key = hashlib.sha1(json.dumps([scene, overrides]).encode()).hexdigest()[:12]
    return os.path.join(out, "runs", key)


def cell_areas(fields):
    """Areas (volumes) of the cells, from the mesh in the output file."""
    x, cells = fields.nodes, fields.topology
    v = x[cells]
    if cells.shape[1] == 3 and x.shape[1] == 2:
        return 0.5 * np.abs(np.cross(v[:, 1] - v[:, 0], v[:, 2] - v[:, 0]))
    a, b, c = (v[:, i] - v[:, 0] for i in (1, 2, 3))
    return np.abs(np.einsum("ij,ij->i", a, np.cross(b, c))) / 6


def values(fields, name, t):
    return fields.at(name, t)


def relative(error, reference, weights=None):
    w = np.ones(len(error)) if weights is None else weights
    num = math.sqrt(float(np.sum(w[:, None] * error.reshape(len(w), -1) ** 2)))
    den = math.sqrt(float(np.sum(w[:, None] * reference.reshape(len(w), -1) ** 2)))
    return num / den if den > 0 else float("nan")


class ClosedFormReference:
    """Terzaghi's closed form at the points of a run (cells and nodes)."""

    def __init__(self, scene_path):
        with open(os.path.join(ROOT, scene_path), "rb") as f:
            s = tomllib.load(f)
        mech, flow, coupling = s["mechanics"], s["flow"], s["coupling"]
        self.y0 = s["mesh"].get("lower", [0.0, 0.0])[1]
        self.terzaghi = Terzaghi(s["mesh"]["upper"][1] - self.y0, mech["G"], mech["lambda"], coupling["alpha"],
                                 1 / flow.get("M", math.inf) + flow.get("c_f", 0.0) * flow.get("phi0", 0.0),
                                 flow["permeability"] / flow["mu_f"], s["reference"]["load"])
        self.description = "Terzaghi's closed form (docs/verification.md)"

    def fields(self, fields, t):
        T, y0 = self.terzaghi, self.y0
        zc = fields.cells[:, 1] - y0
        zn = fields.nodes[:, 1] - y0
        p = np.array([T.pressure(z, t) for z in zc])
        u = np.zeros((len(zn), 3))
        u[:, 1] = [T.displacement(z, t) for z in zn]
        # z = -k/mu_f dp/dz, dp/dz = -(2 p0/h) sum (-1)^(j-1) sin((2j-1) pi z/(2h)) E_j
        dpdz = np.array([-2 * T.initial_pressure() / T.h * T._series(
            z, t, lambda j, k: (1.0 if j % 2 == 1 else -1.0) * np.sin(k * math.pi * z / (2 * T.h))) for z in zc])
        flux = np.zeros((len(zc), 3))
        flux[:, 1] = -T.mobility * dpdz
        return {"pressure": p[:, None], "displacement": u, "flux": flux}


class RunReference:
    """A (finer) run's fields at the points of a coarser one: nodes by
    coordinates (the meshes are nested), cells by the nearest cell midpoint."""

    def __init__(self, directory, description):
        self.fine = Fields(directory)
        self.description = description
        self._maps = {}

    def _map(self, points, fine_points):
        key = (len(points), len(fine_points))
        if key not in self._maps:
            index = np.empty(len(points), dtype=int)
            for start in range(0, len(points), 512):
                d = ((points[start:start + 512, None, :] - fine_points[None, :, :]) ** 2).sum(axis=2)
                index[start:start + 512] = d.argmin(axis=1)
            self._maps[key] = index
        return self._maps[key]

    def fields(self, fields, t):
        times = self.fine.times("pressure")
        tf = min(times, key=lambda s: abs(s - t))
        if abs(tf - t) > 1e-9 * max(abs(t), 1.0):
            return None
        nodes = self._map(fields.nodes, self.fine.nodes)
        cells = self._map(fields.cells, self.fine.cells)
        return {"pressure": values(self.fine, "pressure", tf)[cells],
                "displacement": values(self.fine, "displacement", tf)[nodes],
                "flux": values(self.fine, "flux", tf)[cells]}


def errors(directory, reference):
    """Relative errors of pressure, displacement and flux at every output
    time the reference has: (final, max over time) of each."""
    fields = Fields(directory)
    areas = cell_areas(fields)
    result = {name: [] for name in ("pressure", "displacement", "flux")}
    for t in fields.times("pressure")[1:]:
        exact = reference.fields(fields, t)
        if exact is None:
            continue
        for name in result:
            if t not in fields.series[name]:
                continue  # multirate: displacement at the coarse times only
            w = None if name == "displacement" else areas
            result[name].append(relative(values(fields, name, t) - exact[name], exact[name], w))
    return {name: (v[-1], max(v)) if v else (float("nan"), float("nan")) for name, v in result.items()}


def plots(rows, out, study):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    variants = sorted({r["variant"] for r in rows}, key=lambda v: [r["variant"] for r in rows].index(v))
    files = {}

    def by_variant(x, y, xlabel, ylabel, name, title, data=rows):
        fig, ax = plt.subplots(figsize=(7, 5))
        for v in variants:
            pts = sorted((float(r[x]), float(r[y])) for r in data if r["variant"] == v and float(r[y]) > 0)
            if pts:
                ax.loglog(*zip(*pts), "o-", label=v)
        ax.set_xlabel(xlabel)
        ax.set_ylabel(ylabel)
        ax.set_title(title)
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=8)
        fig.tight_layout()
        fig.savefig(os.path.join(out, name), dpi=110)
        plt.close(fig)
        files[name] = title

    by_variant("wall_time_s", "pressure_error_final", "wall time [s]", "relative pressure error (final time)",
               "error_vs_time.png", f"{study['name']}: pressure error against run time")
    by_variant("wall_time_s", "displacement_error_final", "wall time [s]",
               "relative displacement error (final time)", "displacement_error_vs_time.png",
               f"{study['name']}: displacement error against run time")
    rows_work = [dict(r, work=int(r["flow_solves"]) + int(r["mechanics_solves"]) + int(r["monolithic_solves"]))
                 for r in rows]
    by_variant("work", "pressure_error_final", "flow + mechanics (+ monolithic) solves",
               "relative pressure error (final time)", "work_vs_error.png", f"{study['name']}: work against error",
               data=rows_work)
    # Iterations per step against gamma.
    fig, ax = plt.subplots(figsize=(7, 5))
    for v in variants:
        pts = [(float(r["gamma"]), int(r["coupling_iterations"]) / max(int(r["steps"]), 1))
               for r in rows if r["variant"] == v and r["scheme"] != "monolithic"]
        if pts:
            ax.plot(*zip(*pts), "o", label=v)
    ax.set_xlabel("gamma = alpha^2/(alpha^2 + lambda S)")
    ax.set_ylabel("coupling iterations per mechanics step")
    ax.set_title(f"{study['name']}: iterations per step against gamma")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(os.path.join(out, "iterations_vs_gamma.png"), dpi=110)
    plt.close(fig)
    files["iterations_vs_gamma.png"] = "iterations per step against gamma"
    # Contraction ratio per iteration against the bound (finest level).
    fig, ax = plt.subplots(figsize=(7, 5))
    finest = max(int(r["level"]) for r in rows)
    gamma = None
    for r in rows:
        if int(r["level"]) != finest or r["scheme"] == "monolithic":
            continue
        with open(os.path.join(r["directory"], "iterations.csv")) as f:
            log = [row for row in csv.DictReader(f) if row["ratio"]]
        ax.semilogy([int(x["iteration"]) for x in log], [float(x["ratio"]) for x in log], ".", ms=2,
                    label=r["variant"])
        gamma = float(r["gamma"])
    if gamma is not None:
        ax.axhline(gamma, color="k", lw=1, label=f"gamma = {gamma:.3f}")
    ax.set_xlabel("coupling iteration within the step")
    ax.set_ylabel("||delta sigma^{n+1}|| / ||delta sigma^n||")
    ax.set_title(f"{study['name']}: contraction ratio per iteration (finest level)")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=8, markerscale=4)
    fig.tight_layout()
    fig.savefig(os.path.join(out, "contraction.png"), dpi=110)
    plt.close(fig)
    files["contraction.png"] = "contraction ratio per iteration against gamma"
    return files


def fastest(rows):
    """For each error level (1, 2 and 5 times the decades the runs span), the
    fastest run whose final pressure error is below it."""
    errs = sorted({float(r["pressure_error_final"]) for r in rows if float(r["pressure_error_final"]) > 0})
    if not errs:
        return []
    lines = []
    for exponent in range(math.floor(math.log10(errs[0])), math.ceil(math.log10(errs[-1])) + 1):
        for mantissa in (1, 2, 5):
            level = mantissa * 10.0 ** exponent
            ok = [r for r in rows if 0 < float(r["pressure_error_final"]) <= level]
            if ok and level <= 2 * errs[-1]:
                best = min(ok, key=lambda r: float(r["wall_time_s"]))
                lines.append((level, best))
    return lines


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("study")
    parser.add_argument("--out", required=True)
    parser.add_argument("--binary", default=os.path.join(ROOT, "build", "biotcontact"))
    args = parser.parse_args()
    try:
        study = read_study(args.study)
    except StudyError as e:
        print(f"study: error: {e}", file=sys.stderr)
        return 2
    os.makedirs(os.path.join(args.out, "runs"), exist_ok=True)
    scene = study["scene"]
    levels, variants = study["levels"], study["variants"]

    if study["reference"] == "closed-form":
        reference = ClosedFormReference(scene)
    else:
        overrides = levels[-1]["overrides"] + study.get("reference_overrides", []) + ["coupling.scheme=monolithic"]
        directory = run_directory(args.out, scene, overrides)
        _, cached = run(args.binary, scene, overrides, directory)
        print(f"reference: monolithic on level {len(levels) - 1} ({'cached' if cached else 'computed'})", flush=True)
        reference = RunReference(directory, "monolithic run on the finest level (" + ", ".join(overrides) + ")")

    rows, started, done_time = [], time.time(), 0.0
    total = len(levels) * len(variants)
    for i, (level, variant) in enumerate([(lv, v) for lv in range(len(levels)) for v in variants]):
        overrides = levels[level]["overrides"] + variant["overrides"]
        directory = run_directory(args.out, scene, overrides)
        t0 = time.time()
        try:
            s, cached = run(args.binary, scene, overrides, directory)
        except StudyError as e:
            print(f"study: error: {e}", file=sys.stderr)
            return 3
        spent = time.time() - t0
        if not cached:
            done_time += spent
        e = errors(directory, reference)
        timings = s["timings"]

        def system_time(name):
            """Seconds in a system's solves (summary.json lists only the systems a run has)."""
            return timings[name]["total"] if name in timings else 0.0
        dofs = sum(s["dofs"].values())
        row = {"variant": variant["label"], "scheme": s["scheme"], "q": s["q"], "L": s["L"], "level": level,
               "h": levels[level].get("h", ""), "dt": s["dt"], "dofs": dofs, "steps": s["steps"],
               "coupling_iterations": s["coupling_iterations"], "flow_solves": s["flow_solves"],
               "mechanics_solves": s["mechanics_solves"], "monolithic_solves": s["monolithic_solves"],
               "wall_time_s": s["wall_time_s"], "time_flow_s": system_time("flow"),
               "time_mechanics_s": system_time("mechanics"), "time_monolithic_s": system_time("monolithic"),
               "time_assembly_s": timings["assembly"], "time_output_s": timings["output"],
               "pressure_error_final": e["pressure"][0], "pressure_error_max": e["pressure"][1],
               "displacement_error_final": e["displacement"][0], "displacement_error_max": e["displacement"][1],
               "flux_error_final": e["flux"][0], "flux_error_max": e["flux"][1], "gamma": s["gamma"],
               "reference": study["reference"], "cached": cached, "directory": directory}
        rows.append(row)
        remaining = total - i - 1
        computed = sum(1 for r in rows if not r["cached"])
        eta = done_time / computed * remaining if computed else 0.0
        print(f"[{i + 1}/{total}] {variant['label']}, level {level}: {'cached' if cached else f'{spent:.1f} s'}, "
              f"pressure error {e['pressure'][0]:.3e}; about {eta:.0f} s left", flush=True)

    with open(os.path.join(args.out, "results.csv"), "w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=COLUMNS, extrasaction="ignore")
        writer.writeheader()
        writer.writerows(rows)
    files = plots(rows, args.out, study)
    version = subprocess.run([args.binary, "--version"], capture_output=True, text=True).stdout.strip()
    lines = [f"# Study: {study['name']}", "", study.get("description", ""), "",
             f"- command: `/usr/bin/python3 tools/study.py {args.study} --out {args.out}`",
             f"- machine: {platform.node()}, {os.cpu_count()} cores, {platform.platform()}",
             f"- solver: {version}", f"- date: {datetime.date.today()}",
             f"- scene: `{scene}`; reference: {reference.description}",
             f"- {total} runs taking {sum(float(r['wall_time_s']) for r in rows):.0f} s of solver wall time "
             f"({time.time() - started:.0f} s for this invocation, finished runs reused)",
             "- errors: relative l2 over cell midpoints (pressure, flux; cell-area weighted) and nodes "
             "(displacement), at every output time; 'final' at the end time, 'max' over time", "",
             "## Fastest run for each error level (final-time relative pressure error)", "",
             "| error <= | fastest variant | level | wall time s | coupling iterations | mechanics solves |",
             "|---|---|---|---|---|---|"]
    for level, r in sorted(fastest(rows), key=lambda lr: -lr[0]):
        lines.append(f"| {level:.0e} | {r['variant']} | {r['level']} | {float(r['wall_time_s']):.2f} "
                     f"| {r['coupling_iterations']} | {int(r['mechanics_solves']) + int(r['monolithic_solves'])} |")
    lines += ["", "## Plots", ""]
    for name, title in files.items():
        lines += [f"![{title}]({name})", ""]
    lines += ["## Runs", "", "| variant | level | dt | dofs | wall s | iterations | flow solves | mechanics solves "
              "| p error (final / max) | u error (final / max) | z error (final / max) |", "|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        lines.append(f"| {r['variant']} | {r['level']} | {r['dt']:g} | {r['dofs']} | {float(r['wall_time_s']):.2f} "
                     f"| {r['coupling_iterations']} | {r['flow_solves']} | {int(r['mechanics_solves']) + int(r['monolithic_solves'])} "
                     f"| {r['pressure_error_final']:.2e} / {r['pressure_error_max']:.2e} "
                     f"| {r['displacement_error_final']:.2e} / {r['displacement_error_max']:.2e} "
                     f"| {r['flux_error_final']:.2e} / {r['flux_error_max']:.2e} |")
    with open(os.path.join(args.out, "report.md"), "w") as f:
        f.write("\n".join(lines) + "\n")
    print(f"wrote {args.out}/results.csv, report.md and {len(files)} plots")
    return 0


if __name__ == "__main__":
    sys.exit(main())
