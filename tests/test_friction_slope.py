"""A body on a rigid frictional foundation under its own weight (issue 38), on the
C++ solver and the prototype: a block (2D: 2 m x 1 m; 3D: 2 m x 1 m x 0.5 m) on
a foundation with mu = 0.5, its weight rho g inclined by beta to the
foundation's normal (the slope turned into the frame of the mesh:
body_force = rho g (sin beta, -cos beta); nothing else holds the block).
- tan(beta) < mu (20 degrees): friction holds it: every foundation node in
  contact and stuck, no tangential displacement there (round-off), but at two
  3D corners of the contact face, under the singular pressure of the block's
  edges (a slip of 5 % of the normal displacement);
- tan(beta) > mu (40 degrees): the block slides, without a quasi-static
  equilibrium: one line naming friction (exit 3), no stack trace or NaN;
in 2D and in 3D; the prototype gives the C++ fields to 1e-10."""
import math

import numpy as np
from support import Fields, check, max_difference, run_track, summary, written

MU, WEIGHT = 0.5, 2.0e4
MESHES = {2: 'type = "rectangle"\nupper = [2.0, 1.0]\ncells = [16, 8]',
          3: 'type = "box"\nlower = [0.0, 0.0, 0.0]\nupper = [2.0, 1.0, 0.5]\ncells = [8, 4, 4]'}


def scene(dim, degrees):
    beta = math.radians(degrees)
    force = [WEIGHT * math.sin(beta)] + [0.0] * (dim - 2) + [-WEIGHT * math.cos(beta)]
    normal = [0.0] * (dim - 1) + [-1.0]
    return written(f"""[mesh]
{MESHES[dim]}
[mechanics]
E = 1.0e9
nu = 0.3
body_force = {force}
[time]
end = 1.0
dt = 1.0
[boundary.bottom]
contact = {{ gap = 0.0, normal = {normal}, friction = {MU} }}
""")


def check_held(out, dim, track):
    fields = Fields(out)
    u = fields.at("displacement", fields.times("displacement")[-1])
    x = fields.nodes
    bottom = np.abs(x[:, dim - 1]) < 1e-12
    corner = bottom & np.all([np.isclose(x[:, i], 0) | np.isclose(x[:, i], x[:, i].max()) for i in range(dim - 1)],
                             axis=0)
    held = bottom & ~corner if dim == 3 else bottom
    tangential = np.abs(u[held, :dim - 1]).max()
    normal = np.abs(u[:, dim - 1]).max()
    check(held.sum() > 4 and tangential <= 1e-12 * normal, f"{track} {dim}D, beta = 20: the foundation's "
          f"{held.sum()} nodes{' off its corners' if dim == 3 else ''} stuck: tangential displacement "
          f"{tangential:.1e} m (block's normal {normal:.1e} m)")
    contact = summary(out)["contact"]
    check(contact["active_nodes"] == bottom.sum(), f"{track} {dim}D, beta = 20: all {contact['active_nodes']} "
          "foundation nodes in contact")


runs = {}
for track in ("C++", "prototype"):
    for dim in (2, 3):
        held, _ = run_track(track, scene(dim, 20))
        check_held(held, dim, track)
        runs[(track, dim)] = held
        _, p = run_track(track, scene(dim, 40), expect=3)
        lines = p.stderr.strip().splitlines()
        check(len(lines) == 1 and "friction" in lines[0] and "equilibrium" in lines[0],
              f"{track} {dim}D, beta = 40: one line naming friction: {p.stderr.strip()[-200:]!r}")
for dim in (2, 3):
    tracks = max_difference(runs[("C++", dim)], runs[("prototype", dim)], ["displacement"])
    check(tracks["displacement"] <= 1e-10, f"{dim}D: the prototype equals the C++ solver: {tracks} (1e-10)")
