#!/usr/bin/python3
"""The picture of the displaced fault (docs/fault_depletion.png), from a run
of scenes/fault_depletion.toml:

    build/biotcontact run scenes/fault_depletion.toml --out results/fault_depletion
    /usr/bin/python3 tools/fault_depletion_figure.py results/fault_depletion [--out docs/fault_depletion.png]

The slip along the fault (fault.xdmf, its vertical component: the right
block's displacement relative to the left's) at every output time, against
Jansen and Meulenbroek's closed form at the full depletion, with the
reservoir's extent on each side.
"""
import argparse
import os

import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import meshio  # noqa: E402
import numpy as np  # noqa: E402

E, NU, ALPHA, DP, A, B = 14.95e9, 0.15, 0.9, -25.0e6, 75.0, 150.0  # scenes/fault_depletion.toml


def closed_form(y):
    plateau = (1 - 2 * NU) * ALPHA * abs(DP) / (E / (2 * (1 + NU))) * (B - A)
    y = np.abs(y)
    return np.where(y <= A, plateau, np.where(y <= B, plateau * (B - y) / (B - A), 0.0))


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("run")
    parser.add_argument("--out", default="docs/fault_depletion.png")
    args = parser.parse_args()
    reader = meshio.xdmf.TimeSeriesReader(os.path.join(args.run, "fault.xdmf"))
    points, _ = reader.read_points_cells()
    order = np.argsort(points[:, 1])
    y = points[order, 1]
    fig, ax = plt.subplots(figsize=(7, 4.5))
    for k in range(reader.num_steps):
        t, data, _ = reader.read_data(k)
        if t > 0:
            ax.plot(data["slip"][order, 1], y, color=plt.cm.viridis(k / reader.num_steps), label=f"t = {t:g}")
    ax.plot(closed_form(y), y, "k--", label="closed form, full depletion")
    for edge in (-B, -A, A, B):
        ax.axhline(edge, color="0.8", lw=0.8)
    ax.set_ylim(-300, 300)
    ax.set_xlabel("slip (m): right block up relative to the left")
    ax.set_ylabel("y (m)")
    ax.set_title("Displaced fault: slip under depletion (Jansen and Meulenbroek 2022)")
    ax.legend(loc="lower right", fontsize=8)
    fig.tight_layout()
    fig.savefig(args.out, dpi=110)


if __name__ == "__main__":
    main()
