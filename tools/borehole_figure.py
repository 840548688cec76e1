#!/usr/bin/python3
"""The picture of the borehole scene (docs/borehole.png), from a run of
scenes/borehole.toml:

    build/biotcontact run scenes/borehole.toml --out results/borehole

Left: the formation around the well at the end, coloured by the pore
pressure change, its wall displaced (to scale) towards the off-centre
screen, the contact arc in red. Middle: the contact pressure around the
wall at several times. Right: the drawdown and the contact arc's extent
against time.
"""
import argparse
import os
import sys

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, ROOT)
from python_prototype.output.time_series import Fields  # noqa: E402

R_WALL, R_SCREEN, E = 0.108, 0.0762, 0.0316  # scenes/borehole.toml
EXAGGERATION = 1.0  # the true displacement: an exaggerated one would cross the screen


def wall(fields):
    """The wall's nodes from the lowest point up, and their angles from it (degrees)."""
    nodes = np.flatnonzero(np.isclose(np.hypot(fields.nodes[:, 0], fields.nodes[:, 1]), R_WALL, atol=1e-6))
    angle = np.degrees(np.arctan2(fields.nodes[nodes, 0], -fields.nodes[nodes, 1]))
    order = np.argsort(angle)
    return nodes[order], angle[order]


def arc(fields, t, nodes, angle):
    """The contact arc's extent from the lowest point (degrees)."""
    active = fields.at("contact_active", t)[nodes, 0] > 0.5
    return float(angle[active].max()) if active.any() else 0.0


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("run")
    parser.add_argument("--out", default=os.path.join(ROOT, "docs", "borehole.png"))
    args = parser.parse_args()
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.tri import Triangulation

    fields = Fields(args.run)
    times = fields.times("displacement")
    nodes, angle = wall(fields)
    fig, axes = plt.subplots(1, 3, figsize=(16, 4.5), gridspec_kw={"width_ratios": [1, 1.1, 1.1]})
    ax = axes[0]
    u = fields.at("displacement", times[-1])[:, :2]
    moved = fields.nodes[:, :2] + EXAGGERATION * u
    tri = Triangulation(moved[:, 0], moved[:, 1], fields.topology)
    image = ax.tripcolor(tri, facecolors=fields.at("pressure", times[-1]).ravel() / 1e6, cmap="viridis")
    phi = np.linspace(0, np.pi, 200)
    ax.plot(R_SCREEN * np.sin(phi), -E - R_SCREEN * np.cos(phi), color="k", lw=2, label="screen")
    active = fields.at("contact_active", times[-1])[nodes, 0] > 0.5
    ax.plot(moved[nodes[active], 0], moved[nodes[active], 1], "r.", ms=6, label="in contact")
    ax.set_aspect("equal")
    ax.set_xlim(0, 0.25)
    ax.set_ylim(-0.16, 0.16)
    ax.legend(fontsize=8, loc="upper right")
    ax.set_title("pressure change (MPa) at the end, displaced mesh")
    fig.colorbar(image, ax=ax)

    ax = axes[1]
    shown = times[1::max(1, len(times) // 6)] + times[-1:]
    for t in shown:
        ax.plot(angle, fields.at("contact_pressure", t)[nodes, 0] / 1e6, color=plt.cm.plasma(t / times[-1]),
                label=f"t = {t:g} s")
    ax.set_xlim(0, 30)
    ax.legend(fontsize=8)
    ax.set_xlabel("angle from the low side (degrees)")
    ax.set_ylabel("contact pressure on the screen (MPa)")
    ax.set_title("the formation bears on the screen's low side")

    ax = axes[2]
    lowest = nodes[0]
    ax.plot(times, [-fields.at("pressure", t)[np.argmin(np.linalg.norm(fields.cells[:, :2] - fields.nodes[lowest, :2],
                                                                      axis=1)), 0] / 1e6 for t in times],
            color="tab:blue")
    ax.set_xlabel("t (s)")
    ax.set_ylabel("drawdown beside the low side (MPa)", color="tab:blue")
    twin = ax.twinx()
    twin.plot(times, [arc(fields, t, nodes, angle) for t in times], color="tab:red", drawstyle="steps-post")
    twin.set_ylabel("contact arc from the low side (degrees)", color="tab:red")
    ax.set_title("drawdown and contact")
    fig.tight_layout()
    fig.savefig(args.out, dpi=90)
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
