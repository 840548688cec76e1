#!/usr/bin/python3
"""The picture of the 3D fault scene (docs/fault3d.png), from a run of
scenes/fault3d.toml:

    build/biotcontact run scenes/fault3d.toml --out results/fault3d
    /usr/bin/python3 tools/fault3d_figure.py results/fault3d [--out docs/fault3d.png]

The fault (fault.xdmf) at the last output time, coloured by the length of
its slip, inside the outline of the reservoir (-600 m < z < -500 m).
"""
import argparse
import os

import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import meshio  # noqa: E402
import numpy as np  # noqa: E402

W, RESERVOIR = 1000.0, (-600.0, -500.0)  # scenes/fault3d.toml


def outline(ax, z):
    """The reservoir's top or bottom as a rectangle."""
    corners = np.array([[-W, -W], [W, -W], [W, W], [-W, W], [-W, -W]])
    ax.plot(corners[:, 0], corners[:, 1], z, color="0.5", lw=0.8)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("run")
    parser.add_argument("--out", default="docs/fault3d.png")
    args = parser.parse_args()
    reader = meshio.xdmf.TimeSeriesReader(os.path.join(args.run, "fault.xdmf"))
    points, cells = reader.read_points_cells()
    t, data, _ = reader.read_data(reader.num_steps - 1)
    slip = data["slip"]
    length = np.linalg.norm(slip, axis=1)
    triangles = cells[0].data
    fig = plt.figure(figsize=(8, 6))
    ax = fig.add_subplot(projection="3d")
    surface = ax.plot_trisurf(points[:, 0], points[:, 1], points[:, 2], triangles=triangles, cmap="viridis",
                              linewidth=0.1, edgecolor="0.3")
    surface.set_array(length[triangles].mean(axis=1))
    for z in RESERVOIR:
        outline(ax, z)
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.set_zlabel("z (m)")
    ax.set_zlim(-1000, 0)
    ax.view_init(elev=20, azim=-60)
    fig.colorbar(surface, ax=ax, shrink=0.6, label="slip (m)")
    ax.set_title(f"Fault slip after a 20 MPa depletion of the reservoir (t = {t:g})")
    fig.tight_layout()
    fig.savefig(args.out, dpi=100)


if __name__ == "__main__":
    main()
