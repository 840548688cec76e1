#!/usr/bin/python3
"""The pictures of the fault reactivated by injection
(docs/fault_reactivation.png), from a run of scenes/fault_reactivation.toml:

    build/biotcontact run scenes/fault_reactivation.toml --out results/fault_reactivation
    /usr/bin/python3 tools/fault_reactivation_figure.py results/fault_reactivation [--out docs/fault_reactivation.png]

Left: the largest slip and the slipping length of the fault against time.
Right: the Coulomb stress |t_T| - mu t_N along the fault (fault.xdmf: the
tangential and the effective normal traction) at several times: negative
where the fault sticks, zero where it slips.
"""
import argparse
import os

import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import meshio  # noqa: E402
import numpy as np  # noqa: E402

MU, DAY = 0.6, 86400.0  # scenes/fault_reactivation.toml
ALONG = np.array([0.5, 0.8660254037844386, 0.0])  # the fault's direction, upwards


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("run")
    parser.add_argument("--out", default="docs/fault_reactivation.png")
    args = parser.parse_args()
    reader = meshio.xdmf.TimeSeriesReader(os.path.join(args.run, "fault.xdmf"))
    points, cells = reader.read_points_cells()
    s = points @ ALONG
    order = np.argsort(s)
    segments = np.abs(np.diff(np.sort(s)))
    length_per_node = np.concatenate([[0], segments]) / 2 + np.concatenate([segments, [0]]) / 2
    times, largest, slipping, profiles = [], [], [], []
    for k in range(reader.num_steps):
        t, data, _ = reader.read_data(k)
        state = data["state"][order, 0]
        times.append(t / DAY)
        largest.append(np.linalg.norm(data["slip"], axis=1).max())
        slipping.append(length_per_node[state == 2].sum())
        coulomb = np.linalg.norm(data["tangential_traction"], axis=1) - MU * data["traction"][:, 0]
        profiles.append((t / DAY, coulomb[order]))
    fig, (left, right) = plt.subplots(1, 2, figsize=(11, 4.2))
    left.plot(times, largest, "C0-o", ms=3, label="largest slip")
    left.set_xlabel("time (days)")
    left.set_ylabel("largest slip (m)", color="C0")
    twin = left.twinx()
    twin.plot(times, slipping, "C1-s", ms=3)
    twin.set_ylabel("slipping length (m)", color="C1")
    left.set_title("Slip of the fault under injection")
    for day, coulomb in profiles:
        if day in (5, 10, 15, 20, 25, 30):
            right.plot(np.sort(s), coulomb / 1e6, label=f"day {day:g}",
                       color=plt.cm.viridis(day / 30))
    right.axhline(0, color="0.6", lw=0.8)
    right.set_xlabel("distance along the fault from its centre, upwards (m)")
    right.set_ylabel("Coulomb stress |t_T| - mu t_N (MPa)")
    right.set_title("Coulomb stress along the fault")
    right.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(args.out, dpi=110)


if __name__ == "__main__":
    main()
