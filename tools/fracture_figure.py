#!/usr/bin/python3
"""The README's picture of the fracture scene (docs/fracture.png), from a run
of scenes/fracture.toml:

    build/biotcontact run scenes/fracture.toml --out results/fracture --set mesh.refine=2 --set time.dt=21600
    /usr/bin/python3 tools/fracture_figure.py results/fracture [--out docs/fracture.png]

Left: the pore pressure near the fracture at three times (the boundary layer
the drawdown drives into the formation). Right: the aperture 2 (g + u_y)
along the fracture face every four days: it closes from the tip.
"""
import argparse
import os
import sys

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, ROOT)
from python_prototype.output.time_series import Fields  # noqa: E402

A, G0 = 15.0, 0.005  # the scene's fracture half-height and largest half-aperture (m)
DAY = 86400.0


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("run")
    parser.add_argument("--out", default=os.path.join(ROOT, "docs", "fracture.png"))
    args = parser.parse_args()
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.tri import Triangulation

    fields = Fields(args.run)
    times = fields.times("displacement")
    tri = Triangulation(fields.nodes[:, 0], fields.nodes[:, 1], fields.topology)
    fig, axes = plt.subplots(1, 4, figsize=(16, 4), gridspec_kw={"width_ratios": [1, 1, 1, 1.4]})
    for ax, t in zip(axes[:3], (times[len(times) // 8], times[len(times) // 2], times[-1])):
        p = fields.at("pressure", t).ravel()
        image = ax.tripcolor(tri, facecolors=p / 1e6, cmap="viridis", vmin=26, vmax=36)
        ax.plot([0, A], [0, 0], color="red", lw=3)
        ax.set_xlim(0, 25)
        ax.set_ylim(0, 8)
        ax.set_title(f"pore pressure (MPa), day {t / DAY:.0f}")
        ax.set_xlabel("x: along the height (m)")
        ax.set_ylabel("y: normal to the fracture (m)")
    fig.colorbar(image, ax=axes[2])
    face = np.isclose(fields.nodes[:, 1], 0.0) & (fields.nodes[:, 0] <= A + 1e-9)
    x = fields.nodes[face, 0]
    order = np.argsort(x)
    gap = G0 * np.maximum(0.0, 1 - (x / A) ** 2) ** (2 / 3)
    ax = axes[3]
    colours = plt.cm.plasma
    shown = times[::16] + ([times[-1]] if (len(times) - 1) % 16 else [])
    for t in shown:
        opening = 2 * (gap + fields.at("displacement", t)[face, 1])
        ax.plot(x[order], 1e3 * opening[order], color=colours(t / times[-1]))
    ax.set_xlabel("x: along the fracture face from its centre (m)")
    ax.set_ylabel("aperture 2 (g + u_y) (mm)")
    ax.set_title("the fracture closes from its tip")
    scale = plt.cm.ScalarMappable(cmap=colours, norm=plt.Normalize(0, times[-1] / DAY))
    fig.colorbar(scale, ax=ax, label="day")
    fig.tight_layout()
    fig.savefig(args.out, dpi=90)
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
