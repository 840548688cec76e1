#!/usr/bin/python3
"""The picture of the injection scene (docs/injection_fault3d.png), from a
run of scenes/injection_fault3d.toml:

    build/biotcontact run scenes/injection_fault3d.toml --out results/injection_fault3d
    /usr/bin/python3 tools/injection_figure.py results/injection_fault3d [--out docs/injection_fault3d.png]

The fault (fault.xdmf) seen face on, in its own plane (down dip against
along strike), at three output times: the fluid pressure p_f on its cells
(top row, a log scale) and the length of its slip at its nodes (bottom
row), with the reservoir's top and bottom and the well.
"""
import argparse
import math
import os

import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import matplotlib.colors as mcolors  # noqa: E402
import matplotlib.tri as mtri  # noqa: E402
import meshio  # noqa: E402
import numpy as np  # noqa: E402

DIP, CENTRE, RESERVOIR = math.pi / 3, -550.0, (-600.0, -500.0)  # meshes/fault3d.geo


def down_dip(z):
    """The distance down dip from the fault's centre of the depth z."""
    return (CENTRE - z) / math.sin(DIP)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("run")
    parser.add_argument("--out", default="docs/injection_fault3d.png")
    args = parser.parse_args()
    reader = meshio.xdmf.TimeSeriesReader(os.path.join(args.run, "fault.xdmf"))
    points, cells = reader.read_points_cells()
    steps = [reader.num_steps // 4, reader.num_steps // 2, reader.num_steps - 1]
    data = [reader.read_data(k) for k in steps]
    mesh = mtri.Triangulation(points[:, 1], down_dip(points[:, 2]), cells[0].data)
    p_max = max(np.max(cell_data["pressure"][0]) for _, _, cell_data in data) / 1e6
    slip_max = max(np.linalg.norm(d["slip"], axis=1).max() for _, d, _ in data) * 1e3
    fig, axes = plt.subplots(2, 3, figsize=(13, 4.8), sharex=True, sharey=True, constrained_layout=True)
    # A log scale: the well's cell holds the peak, the fault around it a
    # hundredth of it.
    scale = mcolors.LogNorm(vmin=0.01 * p_max, vmax=p_max)
    for column, (t, point_data, cell_data) in enumerate(data):
        top, bottom = axes[0, column], axes[1, column]
        p_f = np.maximum(np.ravel(cell_data["pressure"][0]) / 1e6, 0.01 * p_max)
        pressure = top.tripcolor(mesh, facecolors=p_f, norm=scale, cmap="viridis")
        slip = bottom.tripcolor(mesh, np.linalg.norm(point_data["slip"], axis=1) * 1e3, vmin=0, vmax=slip_max,
                                cmap="magma", shading="gouraud")
        top.set_title(f"t = {t / 3600:g} h")
        for ax in (top, bottom):
            for z in RESERVOIR:
                ax.axhline(down_dip(z), color="w", lw=0.8, ls="--")
            ax.plot(0, down_dip(CENTRE), "r+", ms=10)
            ax.set_aspect("equal")
        bottom.set_xlabel("along strike, y (m)")
    for row in axes:
        row[0].set_ylabel("down dip (m)")
    axes[0, 0].invert_yaxis()  # shared by every panel: down dip is down
    fig.colorbar(pressure, ax=axes[0], shrink=0.9, label="fault pressure p_f (MPa)")
    fig.colorbar(slip, ax=axes[1], shrink=0.9, label="slip (mm)")
    fig.suptitle("Injection into a fault: pressure and slip on the fault plane (reservoir between the dashed lines, "
                 "well +)")
    fig.savefig(args.out, dpi=90)


if __name__ == "__main__":
    main()
