"""The regular 3D fracture network of Berre et al. (2021), Case 2 (issue 52,
verification 4): nine fractures in the unit cube (scenes/berre_regular.toml),
conductive and blocking, steady flow. C++ on the shipped mesh refined 0 and
1 times: the rock's pressure along the diagonal approaches the benchmark's
reference (the difference at least halved, within 6 % at refine 1); the
blocking profile jumps where the diagonal crosses the planes 0.5, 0.625 and
0.75, the conductive one does not; every fracture balances with its
intersections (1e-10 direct, 1e-8 iterative); the prototype (refine 0,
blocking) and 2 ranks (conductive) give the C++ pressures to 1e-10.
Numbers: docs/verification.md, "What each test verifies"."""
import os
import sys

import numpy as np
from support import ROOT, Fields, check, fault_fields, run_track, scene, summary

sys.path.insert(0, os.path.join(ROOT, "tools"))
from berre_figure import difference, profile  # noqa: E402  (the benchmark's line and reference)
sys.path.insert(0, ROOT)
from python_prototype.output.compare import compare  # noqa: E402

SCENE = scene("berre_regular")
FAULTS = [f"{axis}{k}" for axis in "xyz" for k in (1, 2, 3)]
BLOCKING = [f"fault.{f}.{key}=1.0e-4" for f in FAULTS for key in ("permeability", "normal_permeability")]
VARIANTS = {"conductive": (), "blocking": BLOCKING}
INFLOW = 3 * 0.25 ** 2  # the volume into the cube in its one unit of time


def balance(out, tolerance):
    volumes = summary(out)["fault_volumes"]
    worst = max(abs(v["injected"] + v["exchanged"] + v["intersections"] - v["stored"] - v["outflow"])
                for v in volumes.values()) / INFLOW
    total = abs(sum(v["intersections"] for v in volumes.values())) / INFLOW
    return worst <= tolerance and total <= tolerance, f"{worst:.1e}, {total:.1e} (at most {tolerance:.0e})"


def jumps(out):
    """The pressure's change across the planes 0.5, 0.625 and 0.75, where
    the diagonal crosses them (s = sqrt(3) c): between the samples 0.01
    before and after."""
    s, p = profile(out)
    return [abs(np.interp(np.sqrt(3.0) * c + 0.01, s, p) - np.interp(np.sqrt(3.0) * c - 0.01, s, p))
            for c in (0.5, 0.625, 0.75)]


runs = {}
for variant, sets in VARIANTS.items():
    runs[variant] = [run_track("C++", SCENE, f"mesh.refine={r}", *sets)[0] for r in (0, 1)]
    d = [difference(out, variant) for out in runs[variant]]
    check(d[1] <= d[0] / 2 and d[1] <= 0.06, f"{variant}: the pressure along the diagonal approaches the "
          f"benchmark's reference: {100 * d[0]:.1f} % -> {100 * d[1]:.1f} % (halved, and 6 % at refine 1)")
    balances = [balance(out, tolerance) for out, tolerance in zip(runs[variant], (1e-10, 1e-8))]
    check(all(ok for ok, _ in balances), f"{variant}: every fracture balanced with its intersections, which sum "
          f"to zero, at both levels, of the inflow: {'; '.join(text for _, text in balances)}")
blocking, conductive = jumps(runs["blocking"][1]), jumps(runs["conductive"][1])
check(min(blocking) > 0.1 and max(conductive) < 0.05, f"the pressure across the planes 0.5, 0.625, 0.75 changes by "
      f"{', '.join(f'{j:.3f}' for j in blocking)} where they block (> 0.1; the reference's jumps 0.52, 0.28, 1.52), "
      f"by {', '.join(f'{j:.3f}' for j in conductive)} where they conduct (< 0.05)")
prototype, _ = run_track("prototype", SCENE, *BLOCKING)
rock = np.abs(Fields(prototype).at("pressure", 1.0) - Fields(runs["blocking"][0]).at("pressure", 1.0)).max()
(_, _, a), (_, _, b) = (fault_fields(out, ("pressure",)) for out in (prototype, runs["blocking"][0]))
fault = np.abs(a[-1]["pressure"] - b[-1]["pressure"]).max()
check(max(rock, fault) <= 1e-10, f"blocking: the prototype's pressure the C++'s in the rock ({rock:.1e}) and the "
      f"fractures ({fault:.1e}) (1e-10)")
lines = []
two, _ = run_track("C++", SCENE, ranks=2)
check(compare(runs["conductive"][0], two, 1e-10, out=lines.append) == 0, "conductive: 2 ranks give 1 rank's pressure "
      f"and flux: {'; '.join(line.strip() for line in lines[1:3])}")
