"""Behaviour unchanged: every regression case (tests/regression/cases.py:
each shipped scene, every coupling scheme and solver path) computes, on both
tracks, what tests/regression/record.py recorded before the code was
reshaped: the same coupling iterations at every step, the same summary
counts, the same active contact set at every output time and every final
field equal to 1e-12 relative to its largest value, with the BLAS kernel
it was recorded with. Another kernel rounds otherwise, and the fields are
held to 1e-9 (measured against the record of OpenBLAS's Haswell kernel: at
most 7.2e-11, docs/verification.md; iterations, counts and sets identical).

REGRESSION_TRACKS=prototype (or cpp) checks one track only, and
REGRESSION_CASES=a,b some cases only, while working on one of them."""
import os
import sys
import tempfile

import numpy as np

from support import BINARY, check

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "regression"))
from cases import CASES, COUNTS, HERE, blas_kernel, outcome, run  # noqa: E402

TOLERANCE, OTHER_KERNEL = 1e-12, 1e-9
KERNEL = blas_kernel()

TRACKS = os.environ.get("REGRESSION_TRACKS", "cpp,prototype").split(",")
SELECTED = os.environ.get("REGRESSION_CASES", ",".join(CASES)).split(",")

for case in SELECTED:
    outs = {track: tempfile.mkdtemp(prefix=f"regression-{track}-") for track in TRACKS}
    runs = {track: run(case, track, BINARY, out) for track, out in outs.items()}
    for track, p in runs.items():
        _, stderr = p.communicate(timeout=900)
        label = f"{case} ({track})"
        check(p.returncode == 0, f"{label}: runs ({stderr.strip()[-300:]})")
        now = outcome(outs[track])
        recorded = dict(np.load(os.path.join(HERE, f"{case}.{track}.npz")))
        kernel = str(recorded.pop("blas"))
        tolerance = TOLERANCE if kernel == KERNEL else OTHER_KERNEL
        check(sorted(now) == sorted(recorded), f"{label}: the same fields ({sorted(set(now) ^ set(recorded))})")
        check(np.array_equal(now["iterations"], recorded["iterations"]),
              f"{label}: the same coupling iterations in all {len(recorded['iterations'])} steps")
        differing = [k for k, a, b in zip(COUNTS, now["counts"], recorded["counts"]) if a != b]
        check(not differing, f"{label}: the same summary counts (differing: {differing})")
        if "active_sets" in recorded:
            check(np.array_equal(now["active_sets"], recorded["active_sets"]),
                  f"{label}: the same active contact sets at all {len(recorded['active_sets'])} output times")
        for name in (k for k in recorded if k.startswith("final_")):
            scale = max(np.abs(recorded[name]).max(), 1e-300)
            difference = np.abs(now[name] - recorded[name]).max() / scale
            check(difference <= tolerance, f"{label}: {name[6:]} equal to {difference:.1e} (limit {tolerance:g}, "
                  f"{'the recorded BLAS' if kernel == KERNEL else f'{KERNEL} against the recorded {kernel}'})")
