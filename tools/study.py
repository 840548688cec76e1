#!/usr/bin/python3
"""Error against run time: sweeps a scene over schemes, q, L, dt and mesh
levels with the C++ solver, and writes results.csv, PNG plots and report.md.

Errors are relative l2 errors of pressure, displacement and flux at every
output time (a crack study: of the jump along the crack, the tips' ends
excluded), against a closed form or a monolithic run on the finest level.
Finished runs are kept under DIR/runs and reused when the study is started
again; --replot redraws the plots from DIR/results.csv without running
anything.
"""
import argparse
import collections
import csv
import datetime
import hashlib
import json
import math
import os
import platform
import re
import subprocess
import sys
import time
import tomllib

import h5py
import numpy as np
import scipy.sparse
from scipy.spatial import cKDTree

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, ROOT)
from python_prototype.diagnostics.closed_form import (DisplacedFault, Terzaghi,  # noqa: E402
                                                      jansen_meulenbroek_slip, penny_opening, sneddon_opening)
from python_prototype.output.time_series import Fields  # noqa: E402

COLUMNS = ["variant", "scheme", "q", "L", "level", "h", "dt", "dofs", "steps", "coupling_iterations",
           "flow_solves", "mechanics_solves", "monolithic_solves", "wall_time_s", "time_flow_s",
           "time_mechanics_s", "time_monolithic_s", "time_assembly_s", "time_output_s",
           "pressure_error_final", "pressure_error_max", "displacement_error_final", "displacement_error_max",
           "flux_error_final", "flux_error_max", "opening_error_final", "opening_error_max", "slip_error_final",
           "slip_error_max", "moment_error_final", "fault_pressure_error_final", "fault_pressure_error_max",
           "pressure_space_error_final", "pressure_time_error_final",
           "gamma", "reference", "cached"]


class StudyError(Exception):
    pass


# A study file names a scene (with `overrides` of its own for every run, if
# any), a list of levels (overrides that set h and dt together) and a list
# of variants (overrides that choose scheme, q, L; a "{key}" in them takes
# the level's value of key, e.g. an adaptive tolerance per level; one that
# starts with "-" is a PETSc option); every variant runs on every level.
# `reference`: "closed-form" (Terzaghi), "monolithic" (the finest level's
# monolithic run, computed once and cached; its cell averages over each
# coarse cell and its P1 values at the nodes, on meshes nested or not;
# `reference_scheme` replaces it by a tightly converged split), or a crack's
# closed form: Sneddon's ellipse for the opening ("sneddon"), Phan et al.'s
# slip ("phan") or Jansen and Meulenbroek's trapezoid ("jansen_meulenbroek").
def read_study(path):
    try:
        with open(path, "rb") as f:
            study = tomllib.load(f)
    except FileNotFoundError:
        raise StudyError(f"{path}: study file not found")
    except tomllib.TOMLDecodeError as e:
        raise StudyError(f"{path}: invalid TOML: {e}")
    for key in ("name", "scene", "reference", "levels", "variants"):
        if key not in study:
            raise StudyError(f"{path}: {key}: missing")
    if study["reference"] not in ("closed-form", "monolithic", *FAULT_REFERENCES):
        raise StudyError(f"{path}: reference: must be one of \"closed-form\", \"monolithic\", "
                         + ", ".join(f'"{name}"' for name in FAULT_REFERENCES))
    fault = FAULT_REFERENCES.get(study["reference"])
    if fault and study["reference"] not in study:
        raise StudyError(f"{path}: {study['reference']}: missing (its table: {fault[2]})")
    study.setdefault("metric", fault[0] if fault else "pressure")
    for level in study["levels"]:  # the study's own overrides go into every run
        level["overrides"] = study.get("overrides", []) + level.get("overrides", [])
    return study


def run(binary, scene, overrides, directory):
    """Runs the solver into `directory` unless a finished run with the same
    command is there already; returns (summary, cached)."""
    command = [binary, "run", os.path.join(ROOT, scene), "--out", directory]
    for o in overrides:
        command += o.split() if o.startswith("-") else ["--set", o]
    stamp = os.path.join(directory, "command.json")
    summary = os.path.join(directory, "summary.json")
    if os.path.exists(stamp) and os.path.exists(summary):
        with open(stamp) as f:
            if json.load(f) == command[2:]:
                with open(summary) as g:
                    return json.load(g), True
    p = subprocess.run(command, capture_output=True, text=True)
    if p.returncode != 0 or not os.path.exists(summary):
        # A failed run writes its summary too (status "failed"): never an error measured on it.
        raise StudyError(f"run failed (exit {p.returncode}): {' '.join(command)}: {p.stderr.strip()}")
    with open(stamp, "w") as f:
        json.dump(command[2:], f)
    with open(summary) as f:
        return json.load(f), False


def run_directory(out, scene, overrides):
    key = hashlib.sha1(json.dumps([scene, overrides]).encode()).hexdigest()[:12]
    return os.path.join(out, "runs", key)


def cell_areas(fields):
    """Areas (volumes) of the cells, from the mesh in the output file."""
    x, cells = fields.nodes, fields.topology
    v = x[cells]
    if cells.shape[1] == 3 and x.shape[1] == 2:
        return 0.5 * np.abs(np.cross(v[:, 1] - v[:, 0], v[:, 2] - v[:, 0]))
    a, b, c = (v[:, i] - v[:, 0] for i in (1, 2, 3))
    return np.abs(np.einsum("ij,ij->i", a, np.cross(b, c))) / 6


def values(fields, name, t):
    return fields.at(name, t)


def relative(error, reference, weights=None):
    w = np.ones(len(error)) if weights is None else weights
    num = math.sqrt(float(np.sum(w[:, None] * error.reshape(len(w), -1) ** 2)))
    den = math.sqrt(float(np.sum(w[:, None] * reference.reshape(len(w), -1) ** 2)))
    return num / den if den > 0 else float("nan")


class ClosedFormReference:
    """Terzaghi's closed form at the points of a run (cells and nodes)."""

    def __init__(self, scene_path):
        with open(os.path.join(ROOT, scene_path), "rb") as f:
            s = tomllib.load(f)
        mech, flow, coupling = s["mechanics"], s["flow"], s["coupling"]
        self.y0 = s["mesh"].get("lower", [0.0, 0.0])[1]
        self.terzaghi = Terzaghi(s["mesh"]["upper"][1] - self.y0, mech["G"], mech["lambda"], coupling["alpha"],
                                 1 / flow.get("M", math.inf) + flow.get("c_f", 0.0) * flow.get("phi0", 0.0),
                                 flow["permeability"] / flow["mu_f"], s["reference"]["load"])
        self.description = "Terzaghi's closed form (docs/verification.md)"
        self.sampling = "the closed form at cell midpoints (pressure, flux) and nodes (displacement)"

    def fields(self, fields, t):
        T, y0 = self.terzaghi, self.y0
        zc = fields.cells[:, 1] - y0
        zn = fields.nodes[:, 1] - y0
        p = T.pressure(zc, t)
        u = np.zeros((len(zn), 3))
        u[:, 1] = T.displacement(zn, t)
        # z = -k/mu_f dp/dz, dp/dz = -(2 p0/h) sum (-1)^(j-1) sin((2j-1) pi z/(2h)) E_j
        dpdz = -2 * T.initial_pressure() / T.h * T._series(
            zc, t, lambda j, k: (1.0 if j % 2 == 1 else -1.0) * np.sin(k * math.pi * zc / (2 * T.h)))
        flux = np.zeros((len(zc), 3))
        flux[:, 1] = -T.mobility * dpdz
        return {"pressure": p[:, None], "displacement": u, "flux": flux}


class RunReference:
    """A (finer) run's fields at the points of a coarser one: nodes by the
    finer run's P1 interpolation there (its own node where the meshes nest:
    mesh.refine), cells by the average over each coarse cell (averaging)."""

    def __init__(self, directory, description):
        self.fine = Fields(directory)
        self.description = description
        self.sampling = ("the reference's average over each cell (pressure, flux) and its values at the nodes "
                         "(displacement)")
        self._maps = {}

    def _maps_for(self, fields):
        key = (len(fields.nodes), len(fields.cells))
        if key not in self._maps:
            d = fields.topology.shape[1] - 1
            # The cell on the node's side of a fault (sided_nodes), the
            # weights at the node itself.
            cell = containing_cells(self.fine, sided_nodes(fields))
            weights = barycentric(self.fine, cell, fields.nodes[:, :d])
            self._maps[key] = (self.fine.topology[cell], weights), self.averaging(fields)
        return self._maps[key]

    def averaging(self, fields):
        """The matrix of a coarse cell's average of the fine P0 values: the
        mean of the fine values at the midpoints of the coarse cell's equal
        children (child_midpoints), exact where the meshes nest in 2D (gmsh
        refines triangles as children does), to the fine values' variation
        over a child otherwise. A P0 value is a cell average: the fine value
        read at the coarse midpoint alone is off by the fine cell's own
        offset, a floor that hid everything below 8.3e-4 of the pressure
        error on the Mandel study (docs/schemes.md)."""
        points, rows = child_midpoints(fields)
        cols = containing_cells(self.fine, points)
        A = scipy.sparse.csr_matrix((np.ones(len(rows)), (rows, cols)),
                                    shape=(len(fields.cells), len(self.fine.cells)))
        return A / (len(rows) // len(fields.cells))

    def fields(self, fields, t):
        times = self.fine.times("pressure")
        tf = min(times, key=lambda s: abs(s - t))
        if abs(tf - t) > 1e-9 * max(abs(t), 1.0):
            return None
        (vertices, lam), average = self._maps_for(fields)
        u = values(self.fine, "displacement", tf)
        cellwise = {name: values(self.fine, name, tf).reshape(len(self.fine.cells), -1)
                    for name in ("pressure", "flux")}
        return {"pressure": average @ cellwise["pressure"],
                "displacement": np.einsum("nk,nkj->nj", lam, u[vertices]),
                "flux": average @ cellwise["flux"]}


def children(simplex):
    """A simplex's 2^d children of equal size by its edges' midpoints (the
    red refinement of a triangle; Bey's of a tetrahedron, its inner
    octahedron cut along the diagonal between the midpoints of edges 02 and
    13). `simplex` holds its vertices as rows."""
    p = simplex
    m = {(i, j): (p[i] + p[j]) / 2 for i in range(len(p)) for j in range(i + 1, len(p))}
    if len(p) == 3:
        return [np.array(c) for c in ([p[0], m[0, 1], m[0, 2]], [m[0, 1], p[1], m[1, 2]],
                                      [m[0, 2], m[1, 2], p[2]], [m[0, 1], m[1, 2], m[0, 2]])]
    return [np.array(c) for c in ([p[0], m[0, 1], m[0, 2], m[0, 3]], [m[0, 1], p[1], m[1, 2], m[1, 3]],
                                  [m[0, 2], m[1, 2], p[2], m[2, 3]], [m[0, 3], m[1, 3], m[2, 3], p[3]],
                                  [m[0, 1], m[0, 2], m[0, 3], m[1, 3]], [m[0, 1], m[0, 2], m[1, 2], m[1, 3]],
                                  [m[0, 2], m[0, 3], m[1, 3], m[2, 3]], [m[0, 2], m[1, 2], m[1, 3], m[2, 3]])]


def child_midpoints(fields):
    """The midpoints of each cell's 2^(d levels) equal children (children,
    3 levels in 2D and 2 in 3D: 64 points a cell), as points and the cell
    of each: their mean is the cell average of a field to its variation
    over a child."""
    d = fields.topology.shape[1] - 1
    simplices = [np.eye(d + 1)]
    for _ in range(3 if d == 2 else 2):
        simplices = [c for s in simplices for c in children(s)]
    lam = np.array([s.mean(axis=0) for s in simplices])
    v = fields.nodes[:, :d][fields.topology]
    points = np.einsum("mk,ckj->cmj", lam, v).reshape(-1, d)
    return points, np.repeat(np.arange(len(fields.topology)), len(lam))


def sided_nodes(fields):
    """The nodes moved a little toward the midpoint of the cells around them:
    a fault's two copies of a node (one per face, at the same point) part
    toward their own sides, so a coarse node is matched with the fine cell
    on its side. The move, 1e-3 of the shortest such distance, keeps the
    point in a fine cell at the node (a cell split uniformly has its
    corners' directions on every level)."""
    d = fields.topology.shape[1] - 1
    x = fields.nodes[:, :d]
    count = np.bincount(fields.topology.ravel(), minlength=len(x))
    star = np.stack([np.bincount(fields.topology.ravel(), np.repeat(fields.cells[:, i], d + 1), len(x))
                     for i in range(d)], axis=1) / np.maximum(count, 1)[:, None]
    towards = star - x
    length = np.linalg.norm(towards, axis=1)
    used = length > 0
    step = 1e-3 * length[used].min()
    moved = x.copy()
    moved[used] += step * towards[used] / length[used][:, None]
    return moved


def barycentric(fields, cells, points):
    """The barycentric coordinates (n, d+1) of each point in its cell."""
    d = fields.topology.shape[1] - 1
    v = fields.nodes[:, :d][fields.topology[cells]]
    T = np.stack([v[:, i + 1] - v[:, 0] for i in range(d)], axis=2)
    lam = np.linalg.solve(T, (points - v[:, 0])[..., None])[..., 0]
    return np.concatenate([(1 - lam.sum(axis=1))[:, None], lam], axis=1)


def containing_cells(fields, points):
    """The cell of `fields`' mesh (triangles or tetrahedra) holding each
    point: of the cells with the nearest midpoints (more in 3D, where more
    cells share a node), the one whose smallest barycentric coordinate of
    the point is largest (>= 0 inside; a point on a face goes to either
    side)."""
    d = fields.topology.shape[1] - 1
    y = points[:, :d]
    candidates = 12 if d == 2 else 32
    _, near = cKDTree(fields.cells[:, :d]).query(y, k=min(candidates, len(fields.cells)))
    near = near.reshape(len(y), -1)
    best = np.full(len(y), -np.inf)
    owner = near[:, 0].copy()
    for c in near.T:
        smallest = barycentric(fields, c, y).min(axis=1)
        better = smallest > best
        owner[better], best[better] = c[better], smallest[better]
    return owner


class CrackReference:
    """A straight fault's jump against a closed-form profile along it: the
    fault.h5 field `field` (its norm per node) at the + face's nodes against
    `profile(s)`, s the distance along the fault from its centre; relative
    l2 weighted by the length each node stands for, over |s| <= (1 - tips) a."""

    def __init__(self, crack, metric, field, profile, description, moment=None):
        self.crack, self.metric, self.field, self.profile = crack, metric, field, profile
        self.moment = moment  # the closed form's seismic moment (N m/m), where the slip is measured
        self.description = description
        tips = crack.get("tips", 0.1)
        self.sampling = (f"the closed-form {metric} at the fault's nodes" +
                         (f", the tips' {tips:.0%} of a at each end excluded" if tips else ""))

    def errors(self, directory):
        c = self.crack
        with h5py.File(os.path.join(directory, "fault.h5")) as f:
            x = f["Mesh/geometry"][:]
            last = max(int(k) for k in f[self.field].keys())
            jump = f[f"{self.field}/{last}"][:]
        jump = np.linalg.norm(jump.reshape(len(x), -1), axis=1)
        direction = np.array(c["direction"], dtype=float)
        s = (x[:, :len(direction)] - np.array(c["centre"], dtype=float)) @ (direction / np.linalg.norm(direction))
        order = np.argsort(s)
        s, jump = s[order], jump[order]
        length = np.gradient(s) if len(s) > 1 else np.ones(1)  # half the two neighbouring segments
        inner = np.abs(s) <= (1 - c.get("tips", 0.1)) * c["a"]
        exact = self.profile(s)
        e = relative((jump - exact)[inner], exact[inner], np.abs(length[inner]))
        nan = (float("nan"), float("nan"))
        result = {self.metric: (e, e), "pressure": nan, "displacement": nan, "flux": nan, "moment": nan}
        if self.moment:
            with open(os.path.join(directory, "summary.json")) as f:
                total = json.load(f)["seismic_moment"][c.get("fault", "crack")]["total"]
            result["moment"] = (abs(total / self.moment - 1),) * 2
        return result


def elliptic(amplitude, a):
    """The jump of a straight crack of half-length a in the infinite plane
    under a uniform shear: amplitude sqrt(a^2 - s^2) (Phan's slip)."""
    return lambda s: amplitude * np.sqrt(np.maximum(a ** 2 - s ** 2, 0.0))


def sneddon_reference(c):
    """Sneddon's pressurised crack: the opening, 4 (1 - nu^2) p / E sqrt(a^2 - s^2)."""
    return CrackReference(c, "opening", "opening", lambda s: sneddon_opening(c["p"], c["E"], c["nu"], c["a"], s),
                          f"Sneddon's opening, a = {c['a']} m, E = {c['E']:g} Pa, nu = {c['nu']}, p = {c['p']:g} Pa "
                          "(docs/verification.md)")


def phan_reference(c):
    """Phan et al.'s closed crack under a uniaxial compression sigma at psi to
    its axis, Coulomb friction angle theta: the slip, 4 (1 - nu^2) / E sigma
    sin(psi) (cos(psi) - sin(psi) tan(theta)) sqrt(a^2 - s^2)."""
    psi, theta = math.radians(c["psi"]), math.radians(c["theta"])
    amplitude = 4 * (1 - c["nu"] ** 2) / c["E"] * c["sigma"] * math.sin(psi) * (math.cos(psi) - math.sin(psi)
                                                                                 * math.tan(theta))
    G = c["E"] / (2 * (1 + c["nu"]))
    return CrackReference(c, "slip", "slip", elliptic(amplitude, c["a"]),
                          f"Phan et al.'s frictional slip, a = {c['a']} m, E = {c['E']:g} Pa, nu = {c['nu']}, "
                          f"sigma = {c['sigma']:g} Pa, psi = {c['psi']} deg, theta = {c['theta']} deg "
                          "(docs/verification.md); the seismic moment against G times the slip's integral, "
                          "G amplitude pi a^2 / 2", moment=G * amplitude * math.pi * c["a"] ** 2 / 2)


def jansen_meulenbroek_reference(c):
    """Jansen and Meulenbroek's displaced fault: a depleted reservoir offset
    by a frictionless fault (reservoir_a, reservoir_b: its a and b), whose
    slip is the trapezoid of closed_form.jansen_meulenbroek_slip, measured
    along the whole fault (a its half-length; tips = 0)."""
    fault = DisplacedFault(c["reservoir_a"], c["reservoir_b"])
    return CrackReference(c, "slip", "slip",
                          lambda s: np.abs(jansen_meulenbroek_slip(s, fault, c["E"], c["nu"], c["alpha"], c["dp"])),
                          f"Jansen and Meulenbroek's slip of a displaced fault, reservoir a = {fault.a} m, "
                          f"b = {fault.b} m, E = {c['E']:g} Pa, nu = {c['nu']}, alpha = {c['alpha']}, "
                          f"dp = {c['dp']:g} Pa (docs/verification.md)")


class PennyReference:
    """Sneddon's penny-shaped crack of radius a in the plane through `centre`
    normal to `normal`: the opening at the crack's nodes against
    8 (1 - nu^2) p / (pi E) sqrt(a^2 - r^2), r the distance from the centre
    in the crack's plane; relative l2 weighted by the area each node stands
    for (a third of its triangles'), over r <= (1 - tips) a. The opening is
    fault.h5's at the + face's nodes, or with `symmetric = true` (the body
    on one side, the crack a contact boundary on its plane of symmetry)
    2 u.n at the nodes of the plane (solution.h5)."""

    def __init__(self, c):
        self.c = c
        self.description = (f"Sneddon's penny-shaped crack, a = {c['a']} m, E = {c['E']:g} Pa, nu = {c['nu']}, "
                            f"p = {c['p']:g} Pa (docs/verification.md)")
        self.sampling = (f"the closed-form opening at the crack's nodes, its rim's {c.get('tips', 0.1):.0%} of a "
                         "excluded")

    def crack_face(self, directory):
        """The nodes, the triangles and the opening of the crack's face."""
        if not self.c.get("symmetric", False):
            with h5py.File(os.path.join(directory, "fault.h5")) as f:
                last = max(int(k) for k in f["opening"].keys())
                return f["Mesh/geometry"][:], f["Mesh/topology"][:], f[f"opening/{last}"][:].ravel()
        fields = Fields(directory)
        x, tets = fields.nodes, fields.topology
        n = np.array(self.c["normal"], dtype=float)
        n /= np.linalg.norm(n)
        on = np.abs((x - np.array(self.c["centre"], dtype=float)) @ n) <= 1e-9 * np.abs(x).max()
        faces = np.concatenate([tets[:, f][on[tets[:, f]].all(axis=1)]
                                for f in ((0, 1, 2), (0, 1, 3), (0, 2, 3), (1, 2, 3))])
        u = values(fields, "displacement", fields.times("displacement")[-1]).reshape(len(x), -1)
        return x, faces, 2 * np.abs(u @ n)

    def errors(self, directory):
        c = self.c
        x, triangles, opening = self.crack_face(directory)
        v = x[triangles]
        area = 0.5 * np.linalg.norm(np.cross(v[:, 1] - v[:, 0], v[:, 2] - v[:, 0]), axis=1)
        weight = np.bincount(triangles.ravel(), np.repeat(area / 3, 3), len(x))
        n = np.array(c["normal"], dtype=float)
        d = x - np.array(c["centre"], dtype=float)
        r = np.linalg.norm(d - np.outer(d @ n, n) / (n @ n), axis=1)
        exact = penny_opening(c["p"], c["E"], c["nu"], c["a"], r)
        inner = (weight > 0) & (r <= (1 - c.get("tips", 0.1)) * c["a"])
        e = relative((np.abs(opening) - exact)[inner], exact[inner], weight[inner])
        nan = (float("nan"), float("nan"))
        return {"opening": (e, e), "pressure": nan, "displacement": nan, "flux": nan}


class ConduitReference:
    """The cubic law's transient along a conduit fault from an inlet held at
    p0 + dp: fault.h5's pressure per cell at each output time against
    p0 + dp erfc(s / (2 sqrt(D t))), D = w^2 / (12 mu_f c_f), s the distance
    of the cell's midpoint from the inlet along the fault; relative l2 of
    p_f - exact against exact - p0, weighted by the cells' lengths; (final,
    max over the output times)."""

    def __init__(self, c):
        self.c = c
        self.D = c["w"] ** 2 / (12 * c["mu_f"] * c["c_f"])
        self.description = (f"the cubic law's erfc, w = {c['w']:g} m, mu_f = {c['mu_f']:g} Pa s, c_f = {c['c_f']:g} "
                            f"1/Pa (D = {self.D:.4g} m^2/s), p0 = {c['p0']:g} Pa, dp = {c['dp']:g} Pa "
                            "(docs/verification.md)")
        self.sampling = "the closed-form fault pressure at the fault cells' midpoints, every output time after 0"

    def errors(self, directory):
        c = self.c
        with open(os.path.join(directory, "fault.xdmf")) as f:
            times = [float(t) for t in re.findall(r'<Time Value="([^"]+)"', f.read())]
        with h5py.File(os.path.join(directory, "fault.h5")) as f:
            x = f["Mesh/geometry"][:][f["Mesh/topology"][:]]
            pressures = [f[f"pressure/{i}"][:, 0] for i in range(len(times))]
        direction = np.array(c["direction"], dtype=float)
        ends = (x[..., :len(direction)] - np.array(c["inlet"], dtype=float)) @ (direction / np.linalg.norm(direction))
        s, length = ends.mean(axis=1), np.abs(ends[:, 1] - ends[:, 0])
        history = []
        for t, p in zip(times, pressures):
            if t > 0:
                rise = c["dp"] * np.array([math.erfc(v / (2 * math.sqrt(self.D * t))) for v in s])
                history.append(relative(p - c["p0"] - rise, rise, length))
        nan = (float("nan"), float("nan"))
        return {"fault_pressure": (history[-1], max(history)), "pressure": nan, "displacement": nan, "flux": nan}


# The fault references' metrics, and per reference (metric, constructor,
# the keys of its table in the study file).
FAULT_METRICS = ("opening", "slip", "fault_pressure")
FAULT_REFERENCES = {
    "sneddon": ("opening", sneddon_reference, "a, E, nu, p, centre, direction"),
    "phan": ("slip", phan_reference, "a, E, nu, sigma, psi, theta, centre, direction"),
    "jansen_meulenbroek": ("slip", jansen_meulenbroek_reference,
                           "a, reservoir_a, reservoir_b, E, nu, alpha, dp, centre, direction, tips = 0"),
    "penny": ("opening", PennyReference, "a, E, nu, p, centre, normal, tips = 0.1, symmetric = false"),
    "conduit_erfc": ("fault_pressure", ConduitReference, "w, mu_f, c_f, p0, dp, inlet, direction")}


def errors(directory, reference):
    """Relative errors of pressure, displacement and flux at every output
    time the reference has: (final, max over time) of each; a fault
    reference's own errors instead."""
    if hasattr(reference, "errors"):
        return reference.errors(directory)
    fields = Fields(directory)
    areas = cell_areas(fields)
    result = {name: [] for name in ("pressure", "displacement", "flux")}
    for t in fields.times("pressure")[1:]:
        exact = reference.fields(fields, t)
        if exact is None:
            continue
        for name in result:
            if t not in fields.series[name]:
                continue  # multirate: displacement at the coarse times only
            w = None if name == "displacement" else areas
            result[name].append(relative(values(fields, name, t) - exact[name], exact[name], w))
    return {name: (v[-1], max(v)) if v else (float("nan"), float("nan")) for name, v in result.items()}


# Family colours; grey and black are kept for the monolithic reference and the Pareto front.
FAMILY_COLOURS = ["tab:blue", "tab:orange", "tab:green", "tab:red", "tab:purple", "tab:brown", "tab:pink",
                  "tab:olive", "tab:cyan"]
MARKERS = "osD^vP*Xh<>"
REFERENCE_STYLE = {"color": "0.5", "marker": "o", "linestyle": "-", "lw": 1.5, "ms": 4, "zorder": 2}
FRONT_STYLE = {"color": "black", "marker": "o", "linestyle": "-", "lw": 3.5, "ms": 8, "zorder": 1}


def pyplot():
    """matplotlib's pyplot, drawing to files only (studies run without a display)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    return plt


def family(row):
    """The family a run is coloured and given a panel by: its coupling scheme,
    plus the time scheme when the variant's label names one (" + BDF2",
    " adaptive"). Anderson acceleration is no family but a line style (see
    `styles`), so that it is compared with the same scheme without it."""
    label = row["variant"].lower()
    return row["scheme"] + (" + BDF2" if "bdf2" in label else "") + (" adaptive" if "adaptive" in label else "")


def reference_variant(rows):
    """The plain monolithic variant, drawn in every panel as the reference (None if the study has none)."""
    return next((r["variant"] for r in rows if family(r) == "monolithic"), None)


def panels(rows):
    """[(family, its variants)] in the order of the study, without the
    reference variant (every panel has it) and so without a family left empty."""
    reference, groups = reference_variant(rows), {}
    for r in rows:
        if r["variant"] == reference:
            continue
        group = groups.setdefault(family(r), [])
        if r["variant"] not in group:
            group.append(r["variant"])
    return list(groups.items())


def shade(colour, place, count):
    """The family colour, darker for the first of `count` variants and lighter
    for the last, so that variants of a family differ in shade as well as marker."""
    import matplotlib.colors
    s = 0.6 * place / (count - 1) - 0.3 if count > 1 else 0.0
    rgb = np.array(matplotlib.colors.to_rgb(colour))
    return tuple(rgb * (1 + s) if s < 0 else rgb + (1 - rgb) * s)


def styles(rows):
    """Line style of every variant but the reference: the colour of its family,
    a marker and shade by its place among the family's variants with the same
    acceleration, and dashed lines with open markers for Anderson (so that
    "q = 4" and "q = 4, Anderson" share colour and marker)."""
    result = {}
    for i, (_, variants) in enumerate(panels(rows)):
        colour = FAMILY_COLOURS[i % len(FAMILY_COLOURS)]
        for v in variants:
            anderson = "anderson" in v.lower()
            group = [w for w in variants if ("anderson" in w.lower()) == anderson]
            place = group.index(v)
            c = shade(colour, place, len(group))
            result[v] = {"color": c, "marker": MARKERS[place % len(MARKERS)], "linestyle": "--" if anderson else "-",
                         "markerfacecolor": "white" if anderson else c, "lw": 1.3, "ms": 6, "zorder": 3}
    return result


EQUAL_ERRORS = 0.01


def pareto_front(points):
    """The points no other point beats in both coordinates (another with lower
    or equal x and y): the fastest run at each error level, sorted by x.
    Errors within 1 % count as equal: variants that converge to the same
    discrete solution differ in the last digits only, and a slower one of
    them is no better."""
    front = []
    for x, y in sorted(points):
        if not front or y < (1 - EQUAL_ERRORS) * front[-1][1]:
            front.append((x, y))
    return front


def family_grid(plt, groups, title, sharex=True):
    """A figure with one panel per family, two to a row, the y axes shared so
    that the panels compare at a glance; returns the figure and the panels."""
    ncols = min(len(groups), 2)
    nrows = math.ceil(len(groups) / ncols)
    fig, axes = plt.subplots(nrows, ncols, figsize=(5.5 * ncols, 5.2 * nrows), sharex=sharex, sharey=True,
                             squeeze=False, layout="constrained")
    axes = list(axes.ravel())
    for ax in axes[len(groups):]:
        ax.remove()
    for ax, (name, _) in zip(axes, groups):
        ax.set_title(name)
        # Shared axes label only the outer panels; every panel has its own legend below, so label them all.
        ax.tick_params(which="both", labelbottom=True, labelleft=True)
        ax.grid(True, which="both", alpha=0.3)
    fig.suptitle(title)
    return fig, axes[:len(groups)]


def legend_below(ax, markerscale=1.0):
    """The panel's legend under its axes, clear of the data."""
    ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.16), fontsize=8, markerscale=markerscale)


def draw(ax, points, **style):
    """A log-log line through the points, if there are any."""
    if points:
        ax.loglog(*zip(*points), **style)


# What a plot draws: the columns on its axes and their labels.
PlotAxes = collections.namedtuple("PlotAxes", "x y xlabel ylabel")


def by_family(rows, axes_of, path, title):
    """y against x (`axes_of`: PlotAxes) on log-log axes, one panel per
    family, each with the monolithic reference and the Pareto front of all
    runs (in x and y)."""
    x, y, xlabel, ylabel = axes_of
    plt = pyplot()
    look, reference = styles(rows), reference_variant(rows)
    # A study of the reference alone still gets its panel.
    groups = panels(rows) or [("monolithic", [])]

    def line(variant):
        return sorted((float(r[x]), float(r[y])) for r in rows if r["variant"] == variant and float(r[y]) > 0)
    front = pareto_front([p for v in list(look) + [reference] for p in line(v)])
    fig, axes = family_grid(plt, groups, title)
    for ax, (_, variants) in zip(axes, groups):
        draw(ax, front, **FRONT_STYLE, label="Pareto front (all runs)")
        draw(ax, line(reference), **REFERENCE_STYLE, label=f"{reference} (reference)")
        for v in variants:
            draw(ax, line(v), **look[v], label=v)
        ax.set_xlabel(xlabel)
        ax.set_ylabel(ylabel)
        legend_below(ax)
    fig.savefig(path, dpi=110)
    plt.close(fig)


def plot_iterations(rows, path, title):
    """Coupling iterations per step against gamma. gamma is the same for all
    variants of a scene, so each variant is shifted sideways (within 3 % of
    gamma, in the order of the study) to keep the points from hiding each other."""
    plt = pyplot()
    look = styles(rows)
    split = [r for r in rows if r["scheme"] != "monolithic"]
    variants = [v for v in look if any(r["variant"] == v for r in split)]
    fig, ax = plt.subplots(figsize=(10, 5.5), layout="constrained")
    for i, v in enumerate(variants):
        shift = 1 + 0.06 * ((i + 0.5) / len(variants) - 0.5)
        pts = [(float(r["gamma"]) * shift, int(r["coupling_iterations"]) / max(int(r["steps"]), 1))
               for r in split if r["variant"] == v]
        ax.plot(*zip(*pts), **dict(look[v], linestyle="none"), label=v)
    for gamma in sorted({float(r["gamma"]) for r in split}):
        ax.axvline(gamma, color="black", lw=1, linestyle=":", zorder=1, label=f"gamma = {gamma:.3f} (unshifted)")
    ax.set_xlabel("gamma = alpha^2/(alpha^2 + lambda S), each variant shifted by up to 3 %")
    ax.set_ylabel("coupling iterations per mechanics step")
    ax.set_title(title)
    ax.grid(True, alpha=0.3)
    ax.legend(loc="upper left", bbox_to_anchor=(1.02, 1), fontsize=8)
    fig.savefig(path, dpi=110)
    plt.close(fig)


def iteration_logs(rows):
    """{variant: (iterations, ratios, gamma)} of the split runs on the finest
    level, from iterations.csv in their run directories; runs whose directory
    is gone (results.csv copied without its runs) are left out."""
    finest = max(int(r["level"]) for r in rows)
    logs = {}
    for r in rows:
        path = os.path.join(r["directory"], "iterations.csv") if r.get("directory") else ""
        if int(r["level"]) != finest or r["scheme"] == "monolithic" or not os.path.exists(path):
            continue
        with open(path) as f:
            log = [x for x in csv.DictReader(f) if x["ratio"]]
        logs[r["variant"]] = ([int(x["iteration"]) for x in log], [float(x["ratio"]) for x in log], float(r["gamma"]))
    return logs


def plot_contraction(rows, path, title):
    """The contraction ratio of every coupling iteration on the finest level,
    one panel per family, with gamma, the bound. Draws nothing and returns
    False when no run has its iterations log."""
    logs = iteration_logs(rows)
    if not logs:
        return False
    plt = pyplot()
    look = styles(rows)
    groups = [(name, [v for v in variants if v in logs]) for name, variants in panels(rows)]
    groups = [(name, variants) for name, variants in groups if variants]
    # Iteration counts differ tenfold between families: each panel keeps its own x axis.
    fig, axes = family_grid(plt, groups, title, sharex=False)
    for ax, (_, variants) in zip(axes, groups):
        for v in variants:
            ax.semilogy(logs[v][0], logs[v][1], **dict(look[v], linestyle="none", ms=3, alpha=0.6), label=v)
        for gamma in sorted({logs[v][2] for v in variants}):
            ax.axhline(gamma, color="black", lw=1, label=f"gamma = {gamma:.3f}")
        ax.set_xlabel("coupling iteration within the step")
        ax.set_ylabel("||delta sigma^{n+1}|| / ||delta sigma^n||")
        legend_below(ax, markerscale=2)
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return True


def plots(rows, out, study):
    """Draws the study's plots into `out`; returns {file: title} of those drawn."""
    name, files = study["name"], {}
    if study["metric"] != "pressure":  # a fault study: its error against run time only
        metric = study["metric"]
        by_family(rows, PlotAxes("wall_time_s", f"{metric}_error_final", "wall time [s]", f"relative {metric} error"),
                  os.path.join(out, "error_vs_time.png"), f"{name}: {metric} error against run time")
        return {"error_vs_time.png": f"{name}: {metric} error against run time"}
    rows_work = [dict(r, work=int(r["flow_solves"]) + int(r["mechanics_solves"]) + int(r["monolithic_solves"]))
                 for r in rows]
    pressure = "relative pressure error (final time)"
    for file, data, x, y, xlabel, ylabel, title in (
            ("error_vs_time.png", rows, "wall_time_s", "pressure_error_final", "wall time [s]", pressure,
             "pressure error against run time"),
            ("displacement_error_vs_time.png", rows, "wall_time_s", "displacement_error_final", "wall time [s]",
             "relative displacement error (final time)", "displacement error against run time"),
            ("work_vs_error.png", rows_work, "work", "pressure_error_final", "flow + mechanics (+ monolithic) solves",
             pressure, "work against error")):
        by_family(data, PlotAxes(x, y, xlabel, ylabel), os.path.join(out, file), f"{name}: {title}")
        files[file] = f"{name}: {title}"
    plot_iterations(rows, os.path.join(out, "iterations_vs_gamma.png"), f"{name}: iterations per step against gamma")
    files["iterations_vs_gamma.png"] = "iterations per step against gamma"
    if plot_contraction(rows, os.path.join(out, "contraction.png"),
                        f"{name}: contraction ratio per iteration (finest level)"):
        files["contraction.png"] = "contraction ratio per iteration against gamma"
    else:
        print(f"{out}: no run directory has iterations.csv, contraction.png not drawn")
    return files


def fastest(rows, metric="pressure"):
    """For each error level (1, 2 and 5 times the decades the runs span), the
    fastest run whose final error of `metric` is below it."""
    column = f"{metric}_error_final"
    errs = sorted({float(r[column]) for r in rows if float(r[column]) > 0})
    if not errs:
        return []
    lines = []
    for exponent in range(math.floor(math.log10(errs[0])), math.ceil(math.log10(errs[-1])) + 1):
        for mantissa in (1, 2, 5):
            level = mantissa * 10.0 ** exponent
            ok = [r for r in rows if 0 < float(r[column]) <= level]
            if ok and level <= 2 * errs[-1]:
                best = min(ok, key=lambda r: float(r["wall_time_s"]))
                lines.append((level, best))
    return lines


def make_reference(study, out, binary):
    """The reference the errors are measured against; a monolithic one is run
    (once, then cached) on the finest level."""
    scene, levels = study["scene"], study["levels"]
    if study["reference"] == "closed-form":
        return ClosedFormReference(scene)
    if study["reference"] in FAULT_REFERENCES:
        return FAULT_REFERENCES[study["reference"]][1](study[study["reference"]])
    # `reference_scheme`: where a monolithic run of the finer level costs too
    # much, a split converged far below the runs' errors (its limit is the
    # monolithic solution).
    scheme = study.get("reference_scheme", ["coupling.scheme=monolithic"])
    overrides = levels[-1]["overrides"] + study.get("reference_overrides", []) + scheme
    directory = run_directory(out, scene, overrides)
    _, cached = run(binary, scene, overrides, directory)
    print(f"reference: {' '.join(scheme)} on level {len(levels) - 1} ({'cached' if cached else 'computed'})",
          flush=True)
    return RunReference(directory, "run on the finest level with (" + ", ".join(overrides) + ")")


# A finished run: its summary.json, its errors, whether it was reused and where it is.
RunOutcome = collections.namedtuple("RunOutcome", "summary errors cached directory")


def result_row(study, level, variant, outcome):
    """A row of results.csv (and the run's directory) from a run's outcome."""
    s, e, cached, directory = outcome
    timings = s["timings"]

    def system_time(name):
        """Seconds in a system's solves (summary.json lists only the systems a run has)."""
        return timings[name]["total"] if name in timings else 0.0
    return {"variant": variant["label"], "scheme": s["scheme"], "q": s["q"], "L": s["L"], "level": level,
            "h": study["levels"][level].get("h", ""), "dt": s["dt"], "dofs": sum(s["dofs"].values()),
            "steps": s["steps"], "coupling_iterations": s["coupling_iterations"], "flow_solves": s["flow_solves"],
            "mechanics_solves": s["mechanics_solves"], "monolithic_solves": s["monolithic_solves"],
            "wall_time_s": s["wall_time_s"], "time_flow_s": system_time("flow"),
            "time_mechanics_s": system_time("mechanics"), "time_monolithic_s": system_time("monolithic"),
            "time_assembly_s": timings["assembly"], "time_output_s": timings["output"],
            "pressure_error_final": e["pressure"][0], "pressure_error_max": e["pressure"][1],
            "displacement_error_final": e["displacement"][0], "displacement_error_max": e["displacement"][1],
            "flux_error_final": e["flux"][0], "flux_error_max": e["flux"][1],
            **{f"{m}_error_{when}": e.get(m, (math.nan, math.nan))[i] for m in FAULT_METRICS
               for i, when in enumerate(("final", "max"))},
            "moment_error_final": e.get("moment", (math.nan,))[0],
            "gamma": s["gamma"],
            "reference": study["reference"], "cached": cached, "directory": directory}


def variant_overrides(variant, level):
    """A variant's overrides on a level: "{key}" takes the level's value of
    key (e.g. "time.adaptive.tolerance={tolerance}", a tolerance per level)."""
    try:
        return [o.format_map(level) for o in variant["overrides"]]
    except KeyError as e:
        raise StudyError(f"variant {variant['label']!r}: the level has no {e.args[0]!r} for its overrides")


def run_all(study, out, binary, reference):
    """Runs every variant on every level (reusing finished runs), printing
    progress and the time left; returns the rows of results.csv."""
    scene, levels, variants = study["scene"], study["levels"], study["variants"]
    rows, spent_by_level = [], [[] for _ in levels]
    runs = [(lv, v) for lv in range(len(levels)) for v in variants]
    for i, (level, variant) in enumerate(runs):
        overrides = levels[level]["overrides"] + variant_overrides(variant, levels[level])
        directory = run_directory(out, scene, overrides)
        t0 = time.time()
        s, cached = run(binary, scene, overrides, directory)
        spent = time.time() - t0
        if not cached:
            spent_by_level[level].append(spent)
        e = errors(directory, reference)
        rows.append(result_row(study, level, variant, RunOutcome(s, e, cached, directory)))
        eta = time_left(spent_by_level, [lv for lv, _ in runs[i + 1:]])
        print(f"[{i + 1}/{len(runs)}] {variant['label']}, level {level}: {'cached' if cached else f'{spent:.1f} s'}, "
              f"{study['metric']} error {e[study['metric']][0]:.3e}; about {eta:.0f} s left", flush=True)
    return rows


def time_left(spent_by_level, remaining):
    """The seconds the remaining runs (their levels) should take: a run costs
    the mean of the last level run so far, times the growth from its level
    to the next (the ratio of the last two levels' means, else 4) per level
    further on."""
    means = [sum(t) / len(t) for t in spent_by_level if t]
    last = max((lv for lv, t in enumerate(spent_by_level) if t), default=None)
    if last is None:
        return 0.0
    growth = max(means[-1] / means[-2], 1.0) if len(means) > 1 else 4.0
    return sum(means[-1] * growth ** max(lv - last, 0) for lv in remaining)


def level_dt(level):
    """The time.dt a level's overrides set."""
    for o in level["overrides"]:
        if o.startswith("time.dt="):
            return float(o.split("=", 1)[1])
    raise StudyError("space_part: every level must set time.dt")


def error_split(study, out, binary, reference, rows):
    """With `space_part` in the study (the overrides of a run whose time error
    is negligible, e.g. a BDF2 monolithic run) and `space_part_steps` (16):
    per level, the error of that run on the level's mesh with a step
    space_part_steps times smaller is the space part of the error; each
    run's time part is its distance to that run (the same mesh), at the
    final time, relative to the reference. Adds both to the rows."""
    if "space_part" not in study:
        return
    levels, factor = study["levels"], study.get("space_part_steps", 16)
    for level in range(len(levels)):
        overrides = (levels[level]["overrides"] + study["space_part"]
                     + [f"time.dt={level_dt(levels[level]) / factor!r}"])
        directory = run_directory(out, study["scene"], overrides)
        run(binary, study["scene"], overrides, directory)
        space = errors(directory, reference)["pressure"][0]
        same_mesh = RunReference(directory, "the space-part run")
        for r in rows:
            if r["level"] == level:
                r["pressure_space_error_final"] = space
                r["pressure_time_error_final"] = errors(r["directory"], same_mesh)["pressure"][0]
        print(f"space part of level {level}: pressure error {space:.3e}", flush=True)


def split_table(study, rows):
    """The report's lines on the error split (none without `space_part`)."""
    if "space_part" not in study:
        return []
    lines = ["## The error split into space and time (final-time relative pressure error)", "",
             f"Space part: the error of a run on the level's mesh with `{' '.join(study['space_part'])}` and a step "
             f"{study.get('space_part_steps', 16)} times smaller; time part: each run's distance to that run.", "",
             "| variant | level | dt | total | space part | time part |", "|---|---|---|---|---|---|"]
    for r in rows:
        lines.append(f"| {r['variant']} | {r['level']} | {r['dt']:g} | {r['pressure_error_final']:.2e} "
                     f"| {r['pressure_space_error_final']:.2e} | {r['pressure_time_error_final']:.2e} |")
    return lines + [""]


def observed_orders(study, rows):
    """The report's table of observed orders between successive levels, per
    variant: of the error against h, and of the cost (wall time) against
    the unknowns, or the steps where two levels share the mesh (none where
    the levels give no h)."""
    metric = study["metric"]
    if not all("h" in level for level in study["levels"]):
        return []
    lines = [f"## Observed orders ({metric} error against h, wall time against unknowns or, on one mesh, steps)", "",
             "| variant | levels | h | error | order of the error | unknowns | wall s | order of the cost |",
             "|---|---|---|---|---|---|---|---|"]
    for variant in study["variants"]:
        own = sorted((r for r in rows if r["variant"] == variant["label"]), key=lambda r: int(r["level"]))
        for a, b in zip(own, own[1:]):
            ea, eb = float(a[f"{metric}_error_final"]), float(b[f"{metric}_error_final"])
            ha, hb = float(a["h"]), float(b["h"])
            order = math.log(ea / eb) / math.log(ha / hb) if ea > 0 and eb > 0 else float("nan")
            # Levels on one mesh (dt alone refined): the cost against the steps.
            size = ("dofs" if a["dofs"] != b["dofs"] else "steps")
            cost = math.log(float(b["wall_time_s"]) / float(a["wall_time_s"])) / math.log(int(b[size]) / int(a[size]))
            lines.append(f"| {variant['label']} | {a['level']} -> {b['level']} | {hb:g} | {eb:.2e} | {order:.2f} "
                         f"| {b['dofs']} | {float(b['wall_time_s']):.2f} | {cost:.2f} |")
    return lines + [""]


def write_report(args, study, reference, rows, files, started):
    """DIR/report.md: how the study was run, the fastest run for each error level, the plots and every run."""
    version = subprocess.run([args.binary, "--version"], capture_output=True, text=True).stdout.strip()
    metric = study["metric"]
    sampling = (f"- errors: relative l2 over the cells (pressure, flux; cell-area weighted) and nodes "
                f"(displacement) against {reference.sampling}, at every output time; 'final' at the end time, "
                "'max' over time") if metric == "pressure" else f"- error: relative l2 against {reference.sampling}"
    lines = [f"# Study: {study['name']}", "", study.get("description", ""), "",
             f"- command: `/usr/bin/python3 tools/study.py {args.study} --out {args.out}`",
             f"- machine: {platform.node()}, {os.cpu_count()} cores, {platform.platform()}",
             f"- solver: {version}", f"- date: {datetime.date.today()}",
             f"- scene: `{study['scene']}`; reference: {reference.description}",
             f"- {len(rows)} runs taking {sum(float(r['wall_time_s']) for r in rows):.0f} s of solver wall time "
             f"({time.time() - started:.0f} s for this invocation, finished runs reused)",
             sampling, "", f"## Fastest run for each error level (final-time relative {metric} error)", "",
             "| error <= | fastest variant | level | wall time s | coupling iterations | mechanics solves |",
             "|---|---|---|---|---|---|"]
    for level, r in sorted(fastest(rows, metric), key=lambda lr: -lr[0]):
        lines.append(f"| {level:.0e} | {r['variant']} | {r['level']} | {float(r['wall_time_s']):.2f} "
                     f"| {r['coupling_iterations']} | {int(r['mechanics_solves']) + int(r['monolithic_solves'])} |")
    lines += [""] + observed_orders(study, rows) + split_table(study, rows) + ["## Plots", ""]
    for name, title in files.items():
        lines += [f"![{title}]({name})", ""]
    if metric != "pressure":
        moment = any(math.isfinite(float(r["moment_error_final"])) for r in rows)
        lines += ["## Runs", "", f"| variant | level | dofs | wall s | mechanics solves | {metric} error |"
                  + (" seismic moment's error |" if moment else ""), "|---|---|---|---|---|---|" + ("---|" if moment else "")]
        lines += [f"| {r['variant']} | {r['level']} | {r['dofs']} | {float(r['wall_time_s']):.2f} "
                  f"| {r['mechanics_solves']} | {float(r[f'{metric}_error_final']):.3e} |"
                  + (f" {float(r['moment_error_final']):.3e} |" if moment else "") for r in rows]
        with open(os.path.join(args.out, "report.md"), "w") as f:
            f.write("\n".join(lines) + "\n")
        return
    lines += ["## Runs", "", "| variant | level | dt | dofs | wall s | iterations | flow solves | mechanics solves "
              "| p error (final / max) | u error (final / max) | z error (final / max) |", "|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        lines.append(f"| {r['variant']} | {r['level']} | {r['dt']:g} | {r['dofs']} | {float(r['wall_time_s']):.2f} "
                     f"| {r['coupling_iterations']} | {r['flow_solves']} | {int(r['mechanics_solves']) + int(r['monolithic_solves'])} "
                     f"| {r['pressure_error_final']:.2e} / {r['pressure_error_max']:.2e} "
                     f"| {r['displacement_error_final']:.2e} / {r['displacement_error_max']:.2e} "
                     f"| {r['flux_error_final']:.2e} / {r['flux_error_max']:.2e} |")
    with open(os.path.join(args.out, "report.md"), "w") as f:
        f.write("\n".join(lines) + "\n")


def replot(study, out):
    """Redraws the plots from DIR/results.csv without running anything (report.md
    is left as it is). The run directories are found again from the study file,
    for the contraction plot, where they are still there."""
    try:
        with open(os.path.join(out, "results.csv")) as f:
            rows = list(csv.DictReader(f))
    except FileNotFoundError:
        print(f"study: error: {out}/results.csv: not found", file=sys.stderr)
        return 2
    levels, overrides = study["levels"], {v["label"]: v["overrides"] for v in study["variants"]}
    for r in rows:
        level = int(r["level"])
        known = r["variant"] in overrides and level < len(levels)
        r["directory"] = run_directory(out, study["scene"], levels[level]["overrides"] + overrides[r["variant"]]) \
            if known else ""
    files = plots(rows, out, study)
    print(f"wrote {len(files)} plots to {out}")
    return 0


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("study")
    parser.add_argument("--out", required=True)
    parser.add_argument("--binary", default=os.path.join(ROOT, "build", "biotcontact"))
    parser.add_argument("--replot", action="store_true",
                        help="redraw the plots from OUT/results.csv without running anything")
    args = parser.parse_args()
    try:
        study = read_study(args.study)
    except StudyError as e:
        print(f"study: error: {e}", file=sys.stderr)
        return 2
    if args.replot:
        return replot(study, args.out)
    os.makedirs(os.path.join(args.out, "runs"), exist_ok=True)
    reference = make_reference(study, args.out, args.binary)
    started = time.time()
    try:
        rows = run_all(study, args.out, args.binary, reference)
        error_split(study, args.out, args.binary, reference, rows)
    except StudyError as e:
        print(f"study: error: {e}", file=sys.stderr)
        return 3
    with open(os.path.join(args.out, "results.csv"), "w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=COLUMNS, extrasaction="ignore")
        writer.writeheader()
        writer.writerows(rows)
    files = plots(rows, args.out, study)
    write_report(args, study, reference, rows, files, started)
    print(f"wrote {args.out}/results.csv, report.md and {len(files)} plots")
    return 0


if __name__ == "__main__":
    sys.exit(main())
