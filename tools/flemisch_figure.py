#!/usr/bin/python3
"""The pressure profiles of the fracture networks of Flemisch et al. (2018)
(docs/flemisch.png), from runs of the regular network's two variants and
the complex network's two (scenes/flemisch_regular.toml and
scenes/flemisch_complex.toml; tests/test_flemisch.py makes the variants):

    /usr/bin/python3 tools/flemisch_figure.py CONDUCTIVE BLOCKING TOP_BOTTOM LEFT_RIGHT [--out docs/flemisch.png]

The rock's pressure along each benchmark's line against its published
reference values at points away from the fractures (LINES, REFERENCE: what
tests/test_flemisch.py checks).
"""
import argparse
import os
import sys

import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, ROOT)
from python_prototype.output.time_series import Fields  # noqa: E402

LINES = {"conductive": ((0.0, 0.7), (1.0, 0.7)), "blocking": ((0.0, 0.1), (0.9, 1.0)),
         "top-bottom": ((0.0, 0.5), (1.0, 0.9)), "left-right": ((0.0, 0.5), (1.0, 0.9))}
# The benchmarks' reference pressure (their published data along the
# lines), by x, at points of each line away from the fractures: the regular
# network's conductive and blocking variants, the complex network's flow
# from top to bottom and from left to right.
REFERENCE = {"conductive": {0.2: 1.3332, 0.4: 1.2024, 0.5: 1.1364, 0.7: 1.0955, 0.9: 1.0333},
             "blocking": {0.27: 3.0791, 0.45: 3.1093, 0.54: 2.3250, 0.63: 1.8129, 0.72: 2.0276, 0.81: 1.1514},
             "top-bottom": {0.2: 1.9751, 0.3: 2.1589, 0.4: 3.0083, 0.5: 3.1187, 0.7: 3.5031, 0.9: 3.7768},
             "left-right": {0.2: 3.4609, 0.4: 2.6622, 0.5: 2.5569, 0.7: 1.5470, 0.9: 1.2890}}


def draw_profile(ax, computed, reference, title, xlabel):
    """One panel: the computed profile (s, p) against the reference points
    (s, p)."""
    ax.plot(*computed, label="biotcontact")
    ax.plot(*reference, "o", label="reference (published)")
    ax.set_title(title, fontsize=10)
    ax.set_xlabel(xlabel)
    ax.set_ylabel("pressure")
    ax.legend()


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    for variant in LINES:
        parser.add_argument(variant.replace("-", "_"))
    parser.add_argument("--out", default="docs/flemisch.png")
    args = parser.parse_args()
    figure, axes = plt.subplots(2, 2, figsize=(10, 8))
    for ax, variant in zip(axes.ravel(), LINES):
        run = getattr(args, variant.replace("-", "_"))
        (x0, _), (x1, _) = LINES[variant]
        fields = Fields(run)
        s, p = fields.along("pressure", fields.times("pressure")[-1], *LINES[variant], n=2000)
        network = "regular" if variant in ("conductive", "blocking") else "complex"
        draw_profile(ax, (x0 + s * (x1 - x0), p), (list(REFERENCE[variant]), list(REFERENCE[variant].values())),
                     f"{network}, {variant}: from {LINES[variant][0]} to {LINES[variant][1]}", "x")
    figure.tight_layout()
    figure.savefig(args.out, dpi=100)
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
