#!/usr/bin/python3
"""The pressure along the diagonal of the regular 3D fracture network of
Berre et al. (2021), Case 2 (docs/berre.png), from runs of its conductive
and blocking variants (scenes/berre_regular.toml; tests/test_berre.py makes
the blocking one), each at one or more refinements:

    /usr/bin/python3 tools/berre_figure.py --conductive RUN [RUN ...] --blocking RUN [RUN ...] [--out docs/berre.png]

Prints each run's relative l2 difference from the benchmark's reference
(REFERENCE: what tests/test_berre.py checks) and draws the finest runs'
profiles against it.
"""
import argparse
import os
import sys

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, ROOT)
from python_prototype.output.time_series import Fields  # noqa: E402

LINE = ((0.0, 0.0, 0.0), (1.0, 1.0, 1.0))
# The benchmark's reference pressure along the diagonal (its finest
# solution, published with the benchmark's results), by arc length s from
# the origin, every 0.0866 (s = sqrt(3) k / 20), the ends left out.
# Where the diagonal meets the fractures x = y = z = 0.5 and 0.75 (k = 10
# and 15) the blocking variant jumps: those two are left out of the
# difference (ON_FRACTURES).
S = np.sqrt(3.0) * np.arange(1, 20) / 20
ON_FRACTURES = (9, 14)
REFERENCE = {
    "conductive": [2.1233, 2.0050, 1.8889, 1.7974, 1.7358, 1.6896, 1.6654, 1.6487, 1.6388, 1.6321, 1.6247, 1.6194,
                   1.6139, 1.6071, 1.5990, 1.5779, 1.5027, 1.3236, 1.0644],
    "blocking": [4.8396, 4.7211, 4.6035, 4.5088, 4.4406, 4.3811, 4.3402, 4.3010, 4.2638, 4.2300, 3.6950, 3.6841,
                 3.3970, 3.3811, 3.3639, 1.7216, 1.5552, 1.3339, 1.0651]}


def profile(run, n=2000):
    """(s, p): the rock's pressure of `run` along the diagonal."""
    fields = Fields(run)
    s, p = fields.along("pressure", fields.times("pressure")[-1], *LINE, n=n)
    return np.sqrt(3.0) * s, p


def difference(run, variant):
    """The relative l2 difference from the reference at its points off the
    fractures."""
    s, p = profile(run)
    keep = np.setdiff1d(np.arange(len(S)), ON_FRACTURES)
    reference = np.array(REFERENCE[variant])[keep]
    return np.linalg.norm(np.interp(S[keep], s, p) - reference) / np.linalg.norm(reference)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--conductive", nargs="+", required=True)
    parser.add_argument("--blocking", nargs="+", required=True)
    parser.add_argument("--out", default="docs/berre.png")
    args = parser.parse_args()
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from flemisch_figure import draw_profile  # the panel of the 2D benchmarks' figure
    figure, axes = plt.subplots(1, 2, figsize=(11, 4.5))
    for ax, variant in zip(axes, REFERENCE):
        runs = getattr(args, variant)
        for run in runs:
            print(f"{variant} {run}: {difference(run, variant):.4f} from the reference")
        draw_profile(ax, profile(runs[-1]), (S, REFERENCE[variant]),
                     f"Berre et al. Case 2, {variant}: (0, 0, 0) to (1, 1, 1)", "arc length")
    figure.tight_layout()
    figure.savefig(args.out, dpi=100)
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
