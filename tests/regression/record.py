"""Records what every regression case computes, C++ and prototype, into
tests/regression/<case>.<track>.npz. Run it on the build whose results are
the reference (before a change that must not alter a number), with the
BLAS kernel it computed with:

    /usr/bin/python3 tests/regression/record.py [build/biotcontact]
"""
import os
import sys
import tempfile

import numpy as np

from cases import CASES, HERE, blas_kernel, outcome, run

binary = sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(os.path.dirname(HERE)), "build",
                                                                "biotcontact")
for case in CASES:
    outs = {track: tempfile.mkdtemp(prefix=f"regression-{track}-") for track in ("cpp", "prototype")}
    runs = {track: run(case, track, binary, out) for track, out in outs.items()}
    for track, p in runs.items():
        _, stderr = p.communicate(timeout=900)
        if p.returncode != 0:
            sys.exit(f"{case} ({track}) failed: {stderr.strip()[-400:]}")
        np.savez_compressed(os.path.join(HERE, f"{case}.{track}.npz"), **outcome(outs[track]), blas=blas_kernel())
        print(f"recorded {case} ({track})")
