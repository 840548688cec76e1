"""A conduit fault through a seal (issue 39, item 4's second half; docs/
theory.md "Flow in a fault"), on the C++ solver and the prototype: a
reservoir (y < -1) and an aquifer (y > 1) of 1e-10 m^2 separated by a
sealing layer of 1e-25 m^2 (material regions from gmsh groups), the bottom
held at 2 MPa and the top at 1 MPa, the sides closed; a vertical conduit
fault (residual aperture 1e-4 m) from y = -2 to y = 2 crosses the seal.
Steady flow: the seal's rock carries nothing (1e-9 of the fault's flow); in
the seal the fault carries one flux Q (1e-9), exchanges nothing and p_f falls
linearly; Q is the cubic law w^3 (p_bottom - p_top) / (12 mu_f (L_seal + h))
within 1 % (the drop spans the seal and half a fault cell, h = 0.05 m, either
side); the prototype gives the C++ fields to 1e-10."""
import os

import h5py
import numpy as np
from support import Fields, check, max_difference, run_track, written

W, MU, P_BOTTOM, P_TOP, L_SEAL, H = 1.0e-4, 1.0e-3, 2.0e6, 1.0e6, 2.0, 0.05  # H: the fault's cells
GEO = """SetFactory("Built-in");
h = 0.05; H = 0.5;
Point(1) = {-5, -3, 0, H}; Point(2) = {5, -3, 0, H}; Point(3) = {5, 3, 0, H}; Point(4) = {-5, 3, 0, H};
Point(5) = {-5, -1, 0, H}; Point(6) = {5, -1, 0, H}; Point(7) = {5, 1, 0, H}; Point(8) = {-5, 1, 0, H};
Point(9) = {0, -2, 0, h}; Point(10) = {0, -1, 0, h}; Point(11) = {0, 1, 0, h}; Point(12) = {0, 2, 0, h};
Line(1) = {1, 2}; Line(2) = {2, 6}; Line(3) = {6, 7}; Line(4) = {7, 3}; Line(5) = {3, 4}; Line(6) = {4, 8};
Line(7) = {8, 5}; Line(8) = {5, 1};
Line(9) = {5, 10}; Line(10) = {10, 6}; Line(11) = {8, 11}; Line(12) = {11, 7};
Line(13) = {9, 10}; Line(14) = {10, 11}; Line(15) = {11, 12};
Curve Loop(1) = {1, 2, -10, -9, 8}; Plane Surface(1) = {1};
Curve Loop(2) = {9, 10, 3, -12, -11, 7}; Plane Surface(2) = {2};
Curve Loop(3) = {11, 12, 4, 5, 6}; Plane Surface(3) = {3};
Curve{13} In Surface{1}; Curve{14} In Surface{2}; Curve{15} In Surface{3};
Physical Curve("bottom") = {1}; Physical Curve("top") = {5}; Physical Curve("sides") = {2, 3, 4, 6, 7, 8};
Physical Curve("fault") = {13, 14, 15};
Physical Surface("reservoir") = {1}; Physical Surface("seal") = {2}; Physical Surface("aquifer") = {3};
"""
SCENE = f"""[mesh]
type = "gmsh"
file = "seal.geo"
dimension = 2
[flow]
M = 1.0e20
c_f = 0.0
mu_f = {MU}
permeability = 1.0e-10
initial_pressure = {P_TOP}
[region.seal]
permeability = 1.0e-25
[time]
end = 1.0
dt = 1.0
[boundary.bottom]
pressure = {P_BOTTOM}
[boundary.top]
pressure = {P_TOP}
[fault.fault]
normal = [1.0, 0.0]
flow = "conduit"
residual_aperture = {W}
"""


def fault_cells(out):
    """The fault cells' centroid y, pressure, flux along the fault (y) and
    exchange at the last output."""
    with h5py.File(os.path.join(out, "fault.h5")) as f:
        x, cells = f["Mesh/geometry"][:], f["Mesh/topology"][:]
        last = len(f["pressure"]) - 1
        p, q, e = (f[f"{name}/{last}"][:] for name in ("pressure", "flux", "exchange"))
    return x[cells].mean(axis=1)[:, 1], p[:, 0], q[:, 1], e[:, 0]


def check_seal(track, out):
    y, p, q, exchange = fault_cells(out)
    inside = np.abs(y) < 1
    Q = np.mean(q[inside])
    exact = W ** 3 * (P_BOTTOM - P_TOP) / (12 * MU * (L_SEAL + H))
    fields = Fields(out)
    t = fields.times("flux")[-1]
    flux = np.linalg.norm(fields.at("flux", t), axis=1)
    centroids = fields.nodes[fields.topology].mean(axis=1)[:, 1]
    seal = np.abs(centroids) < 1 - 1e-9
    line = np.polyfit(y[inside], p[inside], 1)
    linear = np.abs(np.polyval(line, y[inside]) - p[inside]).max() / (P_BOTTOM - P_TOP)
    rock = flux[seal].max() * 10.0  # times the seal's width: what it would carry at that rate
    check(rock <= 1e-9 * Q, f"{track}: the seal's rock carries at most {flux[seal].max():.1e} m/s: across its "
          f"10 m, {rock / Q:.1e} of the fault's flow (1e-9)")
    leak = np.abs(exchange[inside]).max() * L_SEAL / Q  # as if every seal cell leaked as much
    check(np.abs(q[inside] - Q).max() <= 1e-9 * Q and leak <= 1e-9 and linear <= 1e-9,
          f"{track}: along the fault through the seal one flux Q = {Q:.6e} m^2/s to "
          f"{np.abs(q[inside] - Q).max() / Q:.1e}, exchange with the seal {leak:.1e} of Q, p_f linear to "
          f"{linear:.1e} of the drop (1e-9, {int(inside.sum())} cells)")
    seal_only = W ** 3 * (P_BOTTOM - P_TOP) / (12 * MU * L_SEAL)
    check(abs(Q / exact - 1) <= 0.01, f"{track}: Q is the cubic law across the seal, w^3 dp/(12 mu_f (L + h)) = "
          f"{exact:.6e}, to {Q / exact - 1:+.2e} (1 %); {Q / seal_only - 1:+.2%} against L alone")


folder = os.path.dirname(written(GEO, "seal.geo"))
path = os.path.join(folder, "seal.toml")
with open(path, "w") as f:
    f.write(SCENE)
runs = {}
for track in ("C++", "prototype"):
    runs[track], _ = run_track(track, path)
    check_seal(track, runs[track])
same = max_difference(runs["C++"], runs["prototype"], ["pressure", "flux"])
check(max(same.values()) <= 1e-10, f"the prototype gives the C++ fields {same} (1e-10)")
