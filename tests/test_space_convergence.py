"""The discretisation's orders in space on Terzaghi: h halved in both
directions ([2,20] -> [4,40] -> [8,80]) with a BDF2 monolithic step small
enough that the time error is below 2 % of the space error. Expected:
- L2 against the closed form (the summary's errors): P0 pressure order 1,
  P1 displacement order 2;
- at the cells' midpoints (tools/study.py's comparison): the mixed method's
  P0 pressure superconverges (order 2), the RT0 flux is order 1.
One column of cells refined in y alone ([1,40] -> [1,80]) keeps the
triangles' width: the flux error does not fall, which is the floor the
Terzaghi study had before its levels were made isotropic. Both tracks."""
import math
import os
import sys

from support import ROOT, TRACKS, check, run_track, scene, summary

sys.path.insert(0, os.path.join(ROOT, "tools"))
import study as study_tool  # noqa: E402

SETTINGS = ["time.end=0.8", "time.dt=0.001", "time.scheme=bdf2", "coupling.scheme=monolithic", "output.every=0.8"]
reference = study_tool.ClosedFormReference("scenes/terzaghi.toml")


def errors(track, cells):
    out, _ = run_track(track, scene("terzaghi"), f"mesh.cells={cells}", *SETTINGS)
    l2 = summary(out)["errors"]
    at_midpoints = study_tool.errors(out, reference)
    return {"pressure L2": l2["pressure_rel_l2"], "displacement L2": l2["displacement_rel_l2"],
            "pressure at midpoints": at_midpoints["pressure"][0], "flux at midpoints": at_midpoints["flux"][0]}


EXPECTED = {"pressure L2": 0.9, "displacement L2": 1.8, "pressure at midpoints": 1.8, "flux at midpoints": 0.9}
for track in TRACKS:
    levels = [errors(track, c) for c in ("[2,20]", "[4,40]", "[8,80]")]
    for coarse, fine in zip(levels, levels[1:]):
        for name, least in EXPECTED.items():
            order = math.log2(coarse[name] / fine[name])
            check(order >= least,
                  f"{track}: {name}: {coarse[name]:.3e} -> {fine[name]:.3e}, order {order:.2f} >= {least}")
    column = [errors(track, c)["flux at midpoints"] for c in ("[1,40]", "[1,80]")]
    check(column[1] > 0.9 * column[0],
          f"{track}: one column refined in y only: flux error {column[0]:.3e} -> {column[1]:.3e} (no longer falls)")
