#!/usr/bin/python3
"""The picture of a fault network's run (docs/network2d.png), from a run of
scenes/network2d.toml:

    build/biotcontact run scenes/network2d.toml --out results/network2d
    /usr/bin/python3 tools/network_figure.py results/network2d [--out docs/network2d.png]

The rock's pressure at the last output (cells) with the fractures drawn
over it: each conduit coloured by its own pressure p_f, the others grey
(their pressure is not theirs to carry).
"""
import argparse
import os
import sys

import h5py
import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.collections import LineCollection  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, ROOT)
from python_prototype.output.time_series import Fields  # noqa: E402


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("run")
    parser.add_argument("--out", default="docs/network2d.png")
    args = parser.parse_args()
    fields = Fields(args.run)
    t = fields.times("pressure")[-1]
    p = np.asarray(fields.at("pressure", t)).ravel() / 1e6
    with h5py.File(os.path.join(args.run, "fault.h5")) as f:
        x, segments = f["Mesh/geometry"][:], f["Mesh/topology"][:]
        p_f = f[f"pressure/{len(f['pressure']) - 1}"][:, 0] / 1e6
    conduit = p_f != 0  # fault.xdmf gives the faults that are no conduit p_f = 0
    low, high = p.min(), max(p.max(), p_f.max())
    figure, ax = plt.subplots(figsize=(10, 5.4))
    shown = ax.tripcolor(fields.nodes[:, 0], fields.nodes[:, 1], fields.topology, facecolors=p, vmin=low, vmax=high,
                         cmap="viridis")
    lines = x[segments][:, :, :2]
    ax.add_collection(LineCollection(lines[~conduit], colors="0.6", linewidths=2.5, linestyles="dashed"))
    ax.add_collection(LineCollection(lines[conduit], array=p_f[conduit], cmap="viridis", norm=shown.norm,
                                     linewidths=3.5))
    ax.add_collection(LineCollection(lines[conduit], colors="k", linewidths=0.5))
    ax.set_aspect("equal")
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.set_title(f"pressure (MPa) at t = {t / 86400:g} days: rock (cells) and conduits (lines); sealing dashed")
    figure.colorbar(shown, ax=ax, shrink=0.8)
    figure.tight_layout()
    figure.savefig(args.out, dpi=90)
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
