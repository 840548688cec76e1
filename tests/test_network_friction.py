"""A contact solve with friction that does not stall on a fracture network
(issue 50), both tracks and both contact paths: 50 frictional fractures
(tools/network_geo.py's draw, seed 1, X and T junctions) in a 1 km x 500 m
rectangle under in-situ stress that keeps every fracture stuck (|tau| /
sigma_n <= 0.354 < 0.6), no flow, the mesh 0.6 times the drawn size.
Asserted: exit 0, the full and condensed paths and the prototype the same
fields (1e-8); every pair away from the junctions stuck within the Coulomb
disc, the frictionless junction pairs sliding and reported as slipping;
friction 0.9 the same fields (1e-8). What failed before and the numbers:
docs/verification.md, "What each test verifies"."""
import os
import sys
import tempfile

import numpy as np

from support import ROOT, check, fault_fields, max_difference, run_track, written

sys.path.insert(0, os.path.join(ROOT, "tools"))
import network_geo  # noqa: E402

FRICTION = 0.6
SIZE = "mesh.size_factor=0.6"
FIELDS = ["displacement"]

network = network_geo.draw(50, 1, (0.0, 0.0, 1000.0, 500.0), 10.0)
geo = os.path.join(tempfile.mkdtemp(prefix="network-"), "network.geo")
network_geo.write_geo(network, geo)
SCENE = written(f"""[scene]
name = "network_friction"
[mesh]
type = "gmsh"
file = "{geo}"
dimension = 2
[mechanics]
E = 20.0e9
nu = 0.25
[time]
end = 1.0
dt = 1.0
[boundary.left]
displacement = {{ x = 0.0 }}
[boundary.bottom]
displacement = {{ y = 0.0 }}
[boundary.right]
traction = [-2.0e7, 0.0]
[boundary.top]
traction = [0.0, -4.0e7]
""" + "".join(f"[fault.{name}]\nfriction = {FRICTION}\n" for name in network["fractures"]))
FAULTS = [f"fault.{name}.friction" for name in network["fractures"]]

full, _ = run_track("C++", SCENE, SIZE, options=["-mechanics_contact_condensed", "false"])
condensed, _ = run_track("C++", SCENE, SIZE, options=["-mechanics_contact_condensed", "true"])
prototype, _ = run_track("prototype", SCENE, SIZE, options=["-mechanics_contact_condensed", "false"])
for label, other in (("the condensed path", condensed), ("the prototype", prototype)):
    d = max_difference(full, other, FIELDS)["displacement"]
    check(d < 1e-8, f"the full path's displacement equals {label}'s: {d:.2e} < 1e-8")

_, _, series = fault_fields(full, names=("slip", "traction", "tangential_traction", "state"))
last = series[-1]
slip = np.linalg.norm(last["slip"], axis=1)
sliding = slip > 1e-9
t_n, t_t = last["traction"][:, 0], np.linalg.norm(last["tangential_traction"], axis=1)
held = ~sliding & (t_n > 0)
ratio = np.max(t_t[held] / t_n[held])
check(ratio <= FRICTION, f"Coulomb's law where the pairs hold: max |t_T| / t_N = {ratio:.3f} <= {FRICTION}")
segments = [(np.array(f[:2]), np.array(f[2:])) for f in network["fractures"].values()]
junctions = np.array([a + st[0] * (b - a) for i, (a, b) in enumerate(segments) for c, d in segments[i + 1:]
                      if (st := network_geo.crossing(a, b, c, d))])
nodes, _, _ = fault_fields(full, names=())
distance = np.array([np.min(np.linalg.norm(junctions - x[:2], axis=1)) for x in nodes])
at_junction = distance < 1e-6
state = last["state"][:, 0]
check(np.array_equal(sliding, at_junction) and slip.max() < 0.01,
      f"only the junctions' frictionless pairs slide: {sliding.sum()} of {len(slip)} pairs, those at the "
      f"{len(junctions)} junctions ({at_junction.sum()} pairs), at most {slip.max():.2e} m")
check(np.all(state[at_junction] == 2) and np.all(state[~at_junction] == 1),
      f"the junctions' pairs slip (state 2), every other pair sticks (1): states {np.unique(state[at_junction])} "
      f"and {np.unique(state[~at_junction])}")

firmer, _ = run_track("C++", SCENE, SIZE, *[f"{key}=0.9" for key in FAULTS])
d = max_difference(full, firmer, FIELDS)["displacement"]
check(d < 1e-8, f"friction 0.9 instead of 0.6: the same displacement ({d:.2e} < 1e-8)")
