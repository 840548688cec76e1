#!/usr/bin/python3
"""The picture of the caprock scene (docs/caprock.png), from a run of
scenes/caprock.toml:

    build/biotcontact run scenes/caprock.toml --out results/caprock

Left: the pore pressure around the well and the fracture zone at the end.
Middle: the effective normal stress on the fracture (its contact pressure)
along its height, at the start, while it opens, and at the end; zero where
it has jacked open. Right: the
pressure at the well and the open height of the fracture against time.
"""
import argparse
import os
import sys

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, ROOT)
from python_prototype.output.time_series import Fields  # noqa: E402

BOTTOM, TOP = -1800.0, -1650.0  # the fracture face on x = 0 (m)
WELL = (0.0, -1810.0)
DAY = 86400.0


def face(fields):
    """The nodes of the fracture face, bottom to top, and their elevations."""
    on = np.flatnonzero(np.isclose(fields.nodes[:, 0], 0.0) & (fields.nodes[:, 1] >= BOTTOM - 1e-9)
                        & (fields.nodes[:, 1] <= TOP + 1e-9))
    on = on[np.argsort(fields.nodes[on, 1])]
    return on, fields.nodes[on, 1]


def open_height(fields, t, nodes, y):
    """The height of the face whose contact is not active."""
    closed = fields.at("contact_active", t)[nodes, 0] > 0.5
    segments = np.diff(y)
    return float(np.sum(segments[~(closed[:-1] & closed[1:])]))


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("run")
    parser.add_argument("--out", default=os.path.join(ROOT, "docs", "caprock.png"))
    args = parser.parse_args()
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.tri import Triangulation

    fields = Fields(args.run)
    times = fields.times("displacement")
    tri = Triangulation(fields.nodes[:, 0], fields.nodes[:, 1], fields.topology)
    fig, axes = plt.subplots(1, 3, figsize=(16, 4.5), gridspec_kw={"width_ratios": [1.2, 1, 1.2]})
    ax = axes[0]
    image = ax.tripcolor(tri, facecolors=fields.at("pressure", times[-1]).ravel() / 1e6, cmap="viridis")
    ax.plot([0, 0], [BOTTOM, TOP], color="red", lw=3)
    ax.plot(*WELL, "w*", ms=12)
    ax.set_xlim(0, 400)
    ax.set_ylim(-1900, -1600)
    ax.set_title(f"pore pressure (MPa), day {times[-1] / DAY:.0f}")
    ax.set_xlabel("x from the well's plane (m)")
    ax.set_ylabel("elevation (m)")
    fig.colorbar(image, ax=ax)

    nodes, y = face(fields)
    ax = axes[1]
    colours = plt.cm.plasma
    opening = [t for t in times if 0 < open_height(fields, t, nodes, y) < TOP - BOTTOM]
    shown = times[:1] + opening[::max(1, len(opening) // 6)] + times[-1:]
    last = max(shown[-2], 1.0)
    for t in shown:
        ax.plot(fields.at("contact_pressure", t)[nodes, 0] / 1e6, y, color=colours(min(t / last, 1.0)),
                label=f"day {t / DAY:.0f}")
    ax.legend(fontsize=8)
    ax.set_xlabel("effective normal stress on the fracture (MPa)")
    ax.set_ylabel("elevation (m)")
    ax.set_title("the fracture jacks open from its base")

    ax = axes[2]
    well = np.argmin(np.linalg.norm(fields.cells[:, :2] - WELL, axis=1))
    days = np.array(times) / DAY
    ax.plot(days, [fields.at("pressure", t)[well, 0] / 1e6 for t in times], color="tab:blue")
    ax.set_xlabel("day")
    ax.set_ylabel("pressure at the well (MPa)", color="tab:blue")
    twin = ax.twinx()
    twin.plot(days, [open_height(fields, t, nodes, y) for t in times], color="tab:red")
    twin.set_ylabel("open height of the fracture (m)", color="tab:red")
    ax.set_title("injection and jacking")
    fig.tight_layout()
    fig.savefig(args.out, dpi=90)
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
