#!/usr/bin/python3
"""The pressure profiles of the regular fracture network of Flemisch et al.
(2018) (docs/flemisch_regular.png), from runs of its two variants:

    build/biotcontact run scenes/flemisch_regular.toml --out results/conductive --set mesh.refine=3
    build/biotcontact run scenes/flemisch_regular.toml --out results/blocking --set mesh.refine=3 \\
        --set fault.f1.permeability=1.0e-4 --set fault.f1.normal_permeability=1.0e-4 ... (f1 to f6)
    /usr/bin/python3 tools/flemisch_figure.py results/conductive results/blocking [--out docs/flemisch_regular.png]

The rock's pressure along the benchmark's lines (conductive: y = 0.7;
blocking: (0, 0.1) to (0.9, 1)) against the benchmark's published reference
values at points away from the fractures (LINES, REFERENCE: also what
tests/test_flemisch.py checks).
"""
import argparse
import os
import sys

import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, ROOT)
from python_prototype.output.time_series import Fields  # noqa: E402

LINES = {"conductive": ((0.0, 0.7), (1.0, 0.7)), "blocking": ((0.0, 0.1), (0.9, 1.0))}
# The benchmark's reference pressure (its published data along the lines),
# by x, at points of each line away from the fractures.
REFERENCE = {"conductive": {0.2: 1.3332, 0.4: 1.2024, 0.5: 1.1364, 0.7: 1.0955, 0.9: 1.0333},
             "blocking": {0.27: 3.0791, 0.45: 3.1093, 0.54: 2.3250, 0.63: 1.8129, 0.72: 2.0276, 0.81: 1.1514}}


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("conductive")
    parser.add_argument("blocking")
    parser.add_argument("--out", default="docs/flemisch_regular.png")
    args = parser.parse_args()
    figure, axes = plt.subplots(1, 2, figsize=(10, 4))
    for ax, variant, run in zip(axes, LINES, (args.conductive, args.blocking)):
        (x0, _), (x1, _) = LINES[variant]
        fields = Fields(run)
        s, p = fields.along("pressure", fields.times("pressure")[-1], *LINES[variant], n=2000)
        ax.plot(x0 + s * (x1 - x0), p, label="biotcontact")
        ax.plot(list(REFERENCE[variant]), list(REFERENCE[variant].values()), "o", label="reference (published)")
        ax.set_title(f"{variant}: from {LINES[variant][0]} to {LINES[variant][1]}")
        ax.set_xlabel("x")
        ax.set_ylabel("pressure")
        ax.legend()
    figure.tight_layout()
    figure.savefig(args.out, dpi=100)
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
