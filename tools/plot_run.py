#!/usr/bin/env python3
"""Quick-look plots of a run, without ParaView: PNGs written into the run
directory.
- contact.png (runs with contact): the contact pressure along the contact
  boundary at N output times, and the active set over time (a space-time
  diagram: which contact nodes touch the foundation when);
- history.png: pressure (cell data, nearest cell centre) and displacement
  (nearest node) at the chosen points over time (default: the centre of the
  bounding box and the centres of its two halves along the longest side);
- coupling.png (split schemes): coupling iterations per step, and the
  contraction ratio of every iteration against gamma (iterations.csv).
Reads summary.json, iterations.csv and solution.xdmf/.h5 (output.xdmf = true)."""
import argparse
import csv
import json
import os
import sys

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, ROOT)
from python_prototype.output.time_series import read_time_series  # noqa: E402


class PlotError(Exception):
    pass


def pyplot():
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    return plt


def save(fig, directory, name):
    """Writes the figure into the run directory; returns its path."""
    fig.tight_layout()
    path = os.path.join(directory, name)
    fig.savefig(path, dpi=100)
    pyplot().close(fig)
    return path


def chosen_times(times, count):
    """`count` output times spread over the run, first and last included."""
    index = np.unique(np.linspace(0, len(times) - 1, min(count, len(times))).round().astype(int))
    return [times[i] for i in index]


def plot_contact(directory, nodes, series, count):
    """Contact pressure along the boundary at several times; active set over time."""
    plt = pyplot()
    boundary = series["contact_boundary"]
    flag = next(iter(boundary.values()))[1][:, 0] > 0.5
    ids = np.flatnonzero(flag)
    # Along the contact boundary: the coordinate with the largest spread there.
    axis = int(np.argmax(np.ptp(nodes[ids], axis=0)))
    ids = ids[np.argsort(nodes[ids, axis])]
    s = nodes[ids, axis]
    times = sorted(series["contact_pressure"])
    fig, (left, right) = plt.subplots(1, 2, figsize=(12, 4.5))
    for t in chosen_times(times, count):
        left.plot(s, series["contact_pressure"][t][1][ids, 0], "-", marker=".", label=f"t = {t:.4g}")
    left.set_xlabel("xyz"[axis] + " along the contact boundary")
    left.set_ylabel("contact pressure")
    left.set_title("contact pressure along the contact boundary")
    left.grid(True, alpha=0.3)
    left.legend(fontsize=8)
    active = np.array([series["contact_active"][t][1][ids, 0] for t in times])
    right.pcolormesh(s, times, active, shading="nearest", cmap="Greys", vmin=0, vmax=1)
    right.set_xlabel("xyz"[axis] + " along the contact boundary")
    right.set_ylabel("time")
    right.set_title(f"active set over time (black: on the foundation; {len(ids)} contact nodes)")
    return save(fig, directory, "contact.png")


def default_points(nodes):
    low, high = nodes.min(axis=0), nodes.max(axis=0)
    centre = (low + high) / 2
    axis = int(np.argmax(high - low))
    points = [centre]
    for f in (0.25, 0.75):
        p = centre.copy()
        p[axis] = low[axis] + f * (high[axis] - low[axis])
        points.append(p)
    return points


def plot_history(directory, nodes, cells, series, points):
    """Pressure and displacement at the points over time."""
    plt = pyplot()
    panels = [name for name in ("pressure", "displacement") if name in series]
    if not panels:
        raise PlotError(f"{directory}/solution.xdmf: neither pressure nor displacement written")
    fig, axes = plt.subplots(1, len(panels), figsize=(6 * len(panels), 4.5), squeeze=False)
    centres = nodes[cells].mean(axis=1)
    for ax, name in zip(axes.flat, panels):
        times = sorted(series[name])
        center = series[name][times[0]][0]
        x = nodes if center == "Node" else centres
        for p in points:
            i = int(np.argmin(np.linalg.norm(x - p[:x.shape[1]], axis=1)))
            label = "(" + ", ".join(f"{c:.3g}" for c in x[i]) + ")"
            values = np.array([series[name][t][1][i] for t in times])
            if name == "displacement":
                for j, c in enumerate("xyz"[:nodes.shape[1]]):
                    ax.plot(times, values[:, j], "-" if j == 0 else "--", label=f"u_{c} at {label}")
            else:
                ax.plot(times, values[:, 0], "-", label=f"p at {label}")
        ax.set_xlabel("time")
        ax.set_ylabel(name)
        ax.set_title(f"{name} at {'the nearest cell centre' if center == 'Cell' else 'the nearest node'}")
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize=8)
    return save(fig, directory, "history.png")


def plot_coupling(directory, summary):
    """Iterations per step; contraction ratio per iteration against gamma."""
    with open(os.path.join(directory, "iterations.csv")) as f:
        rows = [r for r in csv.DictReader(f) if r["gamma"]]  # a single solve's rows have no gamma
    if not rows:
        return None
    plt = pyplot()
    steps = {}
    for r in rows:
        steps[int(r["step"])] = int(r["iteration"])
    ratios = [(k, float(r["ratio"])) for k, r in enumerate(rows) if r["ratio"]]
    gamma = float(rows[0]["gamma"]) if rows[0]["gamma"] else None
    fig, (left, right) = plt.subplots(1, 2, figsize=(12, 4.5))
    left.bar(list(steps), list(steps.values()), color="tab:blue")
    left.set_xlabel("step" if not summary.get("scheme", "").startswith("multirate") else "mechanics step (window)")
    left.set_ylabel("coupling iterations")
    left.set_title(f"{summary.get('scheme', '')}: {len(rows)} coupling iterations")
    if ratios:
        right.semilogy(*zip(*ratios), ".", ms=3, label="contraction ratio")
    if gamma:
        right.axhline(gamma, color="tab:red", label=f"gamma = {gamma:.3g}")
    right.set_xlabel("coupling iteration (over the run)")
    right.set_ylabel("ratio of successive ||delta sigma_v||")
    right.set_title("contraction of the split (Theorem 1 / 2)")
    right.grid(True, which="both", alpha=0.3)
    right.legend(fontsize=8)
    return save(fig, directory, "coupling.png")


def point(text):
    try:
        return np.array([float(v) for v in text.split(",")])
    except ValueError:
        raise argparse.ArgumentTypeError(f"--point {text}: expected X,Y or X,Y,Z") from None


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("directory")
    p.add_argument("--point", type=point, action="append", help="X,Y[,Z]; repeatable")
    p.add_argument("--times", type=int, default=5, help="output times in the contact pressure plot")
    args = p.parse_args(argv)
    d = args.directory
    try:
        for name in ("summary.json", "solution.xdmf", "solution.h5"):
            if not os.path.exists(os.path.join(d, name)):
                raise PlotError(f"{os.path.join(d, name)}: not found (is {d} a run directory written "
                                "with output.xdmf = true?)")
        with open(os.path.join(d, "summary.json")) as f:
            summary = json.load(f)
        nodes, cells, series = read_time_series(d)
        written = []
        if "contact_boundary" in series:
            written.append(plot_contact(d, nodes, series, args.times))
        written.append(plot_history(d, nodes, cells, series, args.point or default_points(nodes)))
        if os.path.exists(os.path.join(d, "iterations.csv")):
            path = plot_coupling(d, summary)
            if path:
                written.append(path)
    except (PlotError, OSError, KeyError, ValueError) as e:
        print(f"plot_run: error: {e}", file=sys.stderr)
        return 2
    for path in written:
        print("wrote " + path)
    return 0


if __name__ == "__main__":
    sys.exit(main())
