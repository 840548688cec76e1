"""Wells (issue 22, item 3): `[well.NAME]` with `position` and `rate = expr`
is a point source (2D) or a vertical segment from `bottom` to `top` (3D);
injection positive; both tracks, the prototype the C++ fields to 1e-12.
- Mass balance in a closed box, every step, to 1e-12: the fluid content (S p
  + alpha div u) equals the injected sum of dt R(t_n), for a 2D point, a 3D
  segment at a growing rate, and a well in a poroelastic box (split, monolithic).
- Where the fluid goes (nothing moving within a step): a point on a vertex
  feeds the cells around it equally, a segment each layer by its length there.
- A well outside the mesh, a segment leaving it or upside down, a rate varying
  in space and a well without [flow]: one line naming the key."""
import subprocess

import numpy as np

from support import PROTOTYPE, ROOT, TRACKS, Fields, check, fluid_content, poroelastic_column, run_track, written

S = 1.0e-9  # 1/M


def box(dimension, well, permeability="1.0e-12", extra=""):
    mesh = ('type = "rectangle"\nupper = [2.0, 10.0]\ncells = [2, 20]' if dimension == 2 else
            'type = "box"\nupper = [2.0, 2.0, 10.0]\ncells = [2, 2, 10]')
    return f"""[scene]
name = "well"
description = "a well in a closed box"
[mesh]
{mesh}
[flow]
M = {1 / S}
mu_f = 1.0e-3
permeability = {permeability}
[time]
end = 3.0e3
dt = 1.0e3
[well.injector]
{well}
{extra}"""


def injected(rate, t):
    """The sum of dt R(t_n) up to t (dt = 1000)."""
    return sum(rate(s) * 1.0e3 for s in np.arange(1.0e3, t + 1.0, 1.0e3))


def mass_balance(track, label, scene_file, rate, alpha=0.0, *sets):
    out, _ = run_track(track, scene_file, *sets)
    fields = Fields(out)
    worst = max(abs(np.sum(fluid_content(fields, t, S, alpha)) - injected(rate, t)) / injected(rate, t)
                for t in fields.times("pressure")[1:])
    check(worst < 1e-12, f"{track}, {label}: the fluid content equals the injected volume at every step "
          f"(largest relative difference {worst:.2e})")
    return out


POINT = "position = [1.0, 5.0]\nrate = 2.0e-6"
SEGMENT = 'position = [0.7, 1.3]\nbottom = 2.5\ntop = 7.5\nrate = "2.0e-6 * t / 1.0e3"'
POROELASTIC = poroelastic_column("bottom")

runs = {}
for track in TRACKS:
    runs[track, "point"] = mass_balance(track, "2D point", written(box(2, POINT)), lambda t: 2.0e-6)
    runs[track, "segment"] = mass_balance(track, "3D segment", written(box(3, SEGMENT)), lambda t: 2.0e-6 * t / 1.0e3)
    poroelastic = written(box(2, POINT, extra=POROELASTIC))
    runs[track, "monolithic"] = mass_balance(track, "2D point, poroelastic, monolithic", poroelastic,
                                             lambda t: 2.0e-6, 0.8, "coupling.scheme=monolithic")
    runs[track, "split"] = mass_balance(track, "2D point, poroelastic, split", poroelastic, lambda t: 2.0e-6, 0.8)

    # Where the fluid goes (nothing moves within a step).
    fields = Fields(run_track(track, written(box(2, POINT, permeability="1.0e-25")))[0])
    content = fluid_content(fields, 1.0e3, S)
    touching = np.any(np.linalg.norm(fields.nodes[fields.topology] - [1.0, 5.0], axis=2) < 1e-12, axis=1)
    fed = content[touching] / (2.0e-6 * 1.0e3)
    away = np.max(np.abs(content[~touching])) / (2.0e-6 * 1.0e3)
    check(np.allclose(fed, 1 / touching.sum(), rtol=1e-8, atol=0) and away < 1e-8,
          f"{track}: a point on a vertex feeds its {touching.sum()} cells in equal parts (elsewhere {away:.1e})")
    fields = Fields(run_track(track, written(box(3, SEGMENT, permeability="1.0e-25")))[0])
    content = fluid_content(fields, 1.0e3, S) / (2.0e-6 * 1.0e3)
    layer = np.floor(fields.cells[:, 2]).astype(int)
    shares = np.array([content[layer == k].sum() for k in range(10)])
    expected = np.array([0, 0, 0.5, 1, 1, 1, 1, 0.5, 0, 0]) / 5
    check(np.max(np.abs(shares - expected)) < 1e-8, f"{track}: the segment feeds each layer in proportion to its "
          f"length there ({', '.join(f'{s:.3f}' for s in shares)})")

for key in ("point", "segment", "monolithic", "split"):
    c = subprocess.run(PROTOTYPE + ["compare", runs["C++", key], runs["prototype", key], "--tolerance", "1e-12"],
                       capture_output=True, text=True, cwd=ROOT)
    check(c.returncode == 0, f"{key}: the prototype gives the C++ fields to 1e-12")

# Bad input: one line naming the key, exit 2, on both tracks.
NO_FLOW = """[scene]
name = "dry"
description = "no flow"
[mesh]
type = "rectangle"
upper = [2.0, 10.0]
cells = [2, 20]
[mechanics]
G = 1.0e9
lambda = 1.0e9
[time]
end = 1.0
dt = 1.0
[boundary.bottom]
clamp = true
[well.injector]
position = [1.0, 5.0]
rate = 1.0
"""
for label, scene_file, key in [
        ("a well outside the mesh", written(box(2, "position = [3.0, 5.0]\nrate = 1.0")), "well.injector.position"),
        ("a segment that leaves the mesh", written(box(3, SEGMENT.replace("top = 7.5", "top = 12.0"))),
         "well.injector.position"),
        ("a rate that varies in space", written(box(2, 'position = [1.0, 5.0]\nrate = "x"')), "well.injector.rate"),
        ("a segment upside down", written(box(3, SEGMENT.replace("top = 7.5", "top = 1.0"))), "well.injector.top"),
        ("a well without [flow]", written(NO_FLOW), "well.injector")]:
    for track in TRACKS:
        _, p = run_track(track, scene_file, expect=2)
        check(len(p.stderr.strip().splitlines()) == 1 and key in p.stderr,
              f"{track}, {label}: one line naming {key}: {p.stderr.strip()!r}")
