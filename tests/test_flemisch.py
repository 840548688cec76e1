"""The fracture networks of Flemisch et al. (2018) (issue 52, verification
3): the regular network (conductive and blocking) and the complex network
(top-bottom and left-right), steady flow. C++ on the shipped meshes refined
0 to 2 times (LEVELS): the pressure along the benchmark's line converges
(the second change at least 1.6 times smaller than the first) and lies
within 1 % of the published reference at refine 2; the regular network's
lines are continuous (conductive) or jump at the fractures (blocking); every
fracture balances with its intersections to 1e-10 of the inflow; the
prototype gives the C++ pressures on the complex network to 1e-10.
Numbers: docs/verification.md, "What each test verifies"."""
import os
import sys

import numpy as np
from support import ROOT, Fields, check, fault_fields, run_track, scene, summary, written

sys.path.insert(0, os.path.join(ROOT, "tools"))
from flemisch_figure import LINES, REFERENCE  # noqa: E402  (the benchmark's lines and reference values)

LEVELS = 3  # the shipped meshes refined 0, 1 and 2 times
BLOCKING = [f"fault.f{i}.{key}=1.0e-4" for i in range(1, 7) for key in ("permeability", "normal_permeability")]
with open(scene("flemisch_complex")) as f:  # the complex network's flow from left to right
    LEFT_RIGHT = written(f.read().replace("[boundary.top]", "[boundary.left]").replace(
        "[boundary.bottom]", "[boundary.right]").replace('"flemisch_complex.geo"', repr(os.path.join(
            ROOT, "meshes", "flemisch_complex.geo")).replace("'", '"')))
VARIANTS = {"conductive": (scene("flemisch_regular"), ()), "blocking": (scene("flemisch_regular"), BLOCKING),
            "top-bottom": (scene("flemisch_complex"), ()), "left-right": (LEFT_RIGHT, ())}


def check_balance(out):
    # relative to the volume into the square, 1 (a unit flux over a unit side, one unit of time)
    volumes = summary(out)["fault_volumes"]
    worst = max(abs(v["injected"] + v["exchanged"] + v["intersections"] - v["stored"] - v["outflow"])
                for v in volumes.values())
    total = abs(sum(v["intersections"] for v in volumes.values()))
    return worst <= 1e-10 and total <= 1e-10, f"{worst:.1e}, {total:.1e}"


def check_variant(variant):
    scene_file, sets = VARIANTS[variant]
    runs = [run_track("C++", scene_file, f"mesh.refine={r}", *sets)[0] for r in range(LEVELS)]
    profiles = [Fields(out).along("pressure", 1.0, *LINES[variant])[1] for out in runs]
    changes = [np.sqrt(np.mean((a - b) ** 2)) for a, b in zip(profiles, profiles[1:])]
    orders = np.log2(np.array(changes[:-1]) / np.array(changes[1:]))
    check(all(order > 0.7 for order in orders), f"{variant}: the pressure along the line converges under "
          f"refinement: rms changes {', '.join(f'{c:.2e}' for c in changes)}, observed orders "
          f"{', '.join(f'{o:.2f}' for o in orders)} (> 0.7)")
    (x0, _), (x1, _) = LINES[variant]
    s = (np.arange(len(profiles[-1])) + 0.5) / len(profiles[-1])
    off = {x: np.interp((x - x0) / (x1 - x0), s, profiles[-1]) / p - 1 for x, p in REFERENCE[variant].items()}
    check(max(abs(e) for e in off.values()) <= 0.01, f"{variant}: at refine {LEVELS - 1} the benchmark's reference pressure "
          f"within {', '.join(f'{100 * e:+.2f} %' for e in off.values())} at x = "
          f"{', '.join(str(x) for x in off)} (1 %)")
    balances = [check_balance(out) for out in runs]
    check(all(ok for ok, _ in balances), f"{variant}: every fracture balanced with its intersections, which sum "
          f"to zero, at every level ({'; '.join(text for _, text in balances)}; 1e-10)")
    return runs, profiles[-1]


runs, profiles = {}, {}
for variant in VARIANTS:
    runs[variant], profiles[variant] = check_variant(variant)
along, diagonal = profiles["conductive"], profiles["blocking"]
x = 0.9 * (np.arange(len(diagonal)) + 0.5) / len(diagonal)  # the diagonal line's x
steps = np.abs(np.diff(diagonal))
crossings = [steps[np.abs(x[1:] - c) < 0.01].max() for c in (0.4, 0.5)]  # where it crosses y = 0.5 and x = 0.5
smooth = np.abs(np.diff(along)).max()
check(smooth <= 0.02 and min(crossings) > 0.1 and steps[np.abs(x[1:] - 0.45) < 0.03].max() <= 0.02,
      f"the conductive fractures leave the pressure continuous along y = 0.7 (largest step between samples "
      f"{smooth:.4f}, 0.02); the blocking fractures y = 0.5 and x = 0.5 make it jump where the diagonal line "
      f"crosses them, by {crossings[0]:.3f} and {crossings[1]:.3f} (> 0.1), continuous between")
for variant in ("left-right",):  # ten fractures, blocking ones among them: the prototype's widest case here
    scene_file, sets = VARIANTS[variant]
    prototype, _ = run_track("prototype", scene_file, *sets)
    rock = np.abs(Fields(prototype).at("pressure", 1.0) - Fields(runs[variant][0]).at("pressure", 1.0)).max()
    (_, _, a), (_, _, b) = (fault_fields(out, ("pressure",)) for out in (prototype, runs[variant][0]))
    fault = np.abs(a[-1]["pressure"] - b[-1]["pressure"]).max()
    check(max(rock, fault) <= 1e-10, f"{variant}: the prototype's pressure the C++'s in the rock ({rock:.1e}) and "
          f"the fractures ({fault:.1e}) (1e-10)")
