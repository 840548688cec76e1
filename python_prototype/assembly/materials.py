"""The material coefficients of the forms, cell by cell: the scene's
top-level values in cells in no region, a region's own in its cells
(cpp/assembly/materials.h)."""
import typing
from dataclasses import dataclass

import numpy as np
from dolfinx import fem

from ..scene.input import Acceleration, CouplingScheme, Fallback
from ..scene.scene import agree_on_error
from .parameters import derive_parameters, resistivity

SCALARS = (("G", "G"), ("lmbda", "lmbda"), ("alpha", "alpha"), ("storage", "storage"), ("L", "L"))

# Above this gamma the split's contraction theorems guarantee almost nothing
# (docs/theory.md): the run and `check` warn.
HIGH_GAMMA = 0.99


class GammaPeak(typing.NamedTuple):
    """Where gamma = alpha^2/(alpha^2 + lambda S) is largest over the
    materials that hold cells: its value and the region that reaches it (""
    for the top-level material; on a tie the top-level material, then the
    first region in name order; cpp/assembly/materials.h)."""
    gamma: float
    region: str


def largest_gamma(top, regions, cells):
    """The largest gamma of the materials `top` (the cells in no region) and
    `regions` (in the order of cells.names) that hold cells."""
    peak = GammaPeak(top.gamma if cells.outside > 0 else 0.0, "")
    for name, p in zip(cells.names, regions):
        if p.gamma > peak.gamma:
            peak = GammaPeak(p.gamma, name)
    return peak


def largest_gamma_of(scene, cells):
    """The same from the scene's values (what `check` reads, without the forms)."""
    return largest_gamma(derive_parameters(scene), [derive_parameters(scene, scene.regions[n]) for n in cells.names],
                         cells)


def split_advice(peak, coupling):
    """What to know of a split at this gamma and what converges instead, in
    one sentence (cpp/assembly/materials.h): the one wording of the gamma
    warning and of the error of a split that did not converge."""
    advice = f"gamma = {peak.gamma:.7g}" + (f" in region {peak.region}" if peak.region else "")
    if peak.gamma > HIGH_GAMMA:
        advice += (f" > {HIGH_GAMMA:.7g}: the contraction theorems guarantee almost nothing, expect many coupling "
                   "iterations or none converging")
    # docs/theory.md, "Anderson acceleration": its iterates are not bound to
    # contract by gamma each.
    advice += '; instead: coupling.scheme = "monolithic" (no coupling iteration: the robust choice)'
    if coupling.scheme != CouplingScheme.monolithic and coupling.fallback == Fallback.none:
        advice += ', coupling.fallback = "monolithic" (that scheme for the steps the split fails at)'
    if coupling.acceleration != Acceleration.anderson:
        advice += ', coupling.acceleration = "anderson" (not bound to gamma per iteration)'
    if peak.gamma <= HIGH_GAMMA:
        advice += ", a larger coupling.max_iterations (each iteration contracts by gamma or better)"
    return advice


def gamma_warning(scene, peak):
    """The warning of a split scene whose gamma exceeds HIGH_GAMMA, "" for any
    other (what the run and `check` print)."""
    if not scene.coupling or scene.coupling.scheme == CouplingScheme.monolithic or peak.gamma <= HIGH_GAMMA:
        return ""
    return split_advice(peak, scene.coupling)


class Materials:
    """The parameters of the top-level material and of each region, and over
    the materials that hold cells the largest gamma and L and the smallest S
    and S + L. The DG0 coefficients G, lmbda, alpha, storage, L and
    resistivity live in the forms (Forms), set by make_materials."""

    def __init__(self, top, regions, cells):
        self.top, self.regions = top, regions
        used = ([top] if cells.outside > 0 else []) + regions
        self.gamma, self.gamma_region = largest_gamma(top, regions, cells)
        self.max_L = max(p.L for p in used)
        self.min_storage = min(p.storage for p in used)
        self.min_stabilised_storage = min(p.storage + p.L for p in used)

    def gamma_peak(self):
        return GammaPeak(self.gamma, self.gamma_region)

    def without_stabilisation(self, F, into):
        """Sets the coefficients of F into the forms `into` with L = 0 (the
        second pass of "multirate-two-pass"); the materials of that pass."""
        for name, _ in SCALARS:
            into[name].x.array[:] = 0.0 if name == "L" else F[name].x.array
        into["resistivity"].x.array[:] = F["resistivity"].x.array
        m = Materials.__new__(Materials)
        m.__dict__.update(self.__dict__)
        m.max_L, m.min_stabilised_storage = 0.0, self.min_storage
        return m


def _per_cell(f, components, value):
    """Interpolates into a DG0 function a value per cell: value(cells, x)
    returns the components at the midpoints x of the cells (dolfinx
    interpolates into DG0 at one point per cell, the cells in their local order)."""
    def values(x):
        v = value(np.arange(x.shape[1]), x)
        return v if components > 1 else v.reshape(-1)
    f.interpolate(values)


def _set_resistivity(R, scene, cells, d):
    """mu_f K^-1 cell by cell; the first permeability that is not positive on this rank, or ''."""
    flows = [scene.flow] + [scene.regions[name].flow for name in cells.names]
    error = []

    def value(c, x):
        v = np.zeros((d * d, x.shape[1]))
        region = cells.region[c]
        for r in np.unique(region):
            at = np.flatnonzero(region == r)
            values, bad = resistivity(flows[r + 1], d, x[:, at])
            v[:, at] = values
            if len(bad) and not error:
                p = x[:, at[bad[0]]]
                key = "flow" if r < 0 else "region." + cells.names[r]
                where = ", ".join(f"{c:g}" for c in p[:d])
                error.append(f"{scene.file}: {key}.permeability: must be positive at ({where})")
        return v
    _per_cell(R, d * d, value)
    return error[0] if error else ""


def _set_body_force(f, scene, cells, d, t):
    """Each cell's body force at time t: its material's, zero where none is given."""
    forces = [scene.mechanics.body_force] + [scene.regions[name].mechanics.body_force for name in cells.names]

    def value(c, x):
        v = np.zeros((d, x.shape[1]))
        region = cells.region[c]
        for r in np.unique(region):
            at = np.flatnonzero(region == r)
            if forces[r + 1]:
                v[:, at] = np.vstack([e.at(x[:, at], t) for e in forces[r + 1]])
        return v
    _per_cell(f, d, value)


@dataclass
class BodyForceTerm:
    """The body force term of a step: the names of its two forms, with the
    nodal coefficient "body_force" (P1) and the cell-wise one
    "body_force_cells" (DG0)."""
    nodal: str
    cellwise: str


def add_body_force(loads, scene, domain, F, term):
    """Adds the BodyForceTerm `term` to a step's loads (cpp/assembly/materials.h):
    the scene's body_force interpolated at the nodes into P1, or, when some
    region gives its own, each cell's material's, one value per cell, so that
    a force changes across a region's boundary without smearing over the
    nodes there; nothing when no body force is given."""
    if not scene.cellwise_body_force():
        if scene.mechanics.body_force:
            loads.add(F.compile(term.nodal), F["body_force"], scene.mechanics.body_force)
        return
    forces = [scene.mechanics.body_force] + [r.mechanics.body_force for r in scene.regions.values()]
    time_dependent = any(e.depends_on_time for force in forces if force for e in force)
    loads.add_filled(F.compile(term.cellwise), F["body_force_cells"],
                     lambda f, t: _set_body_force(f, scene, domain.regions, domain.dim, t), time_dependent)


def make_materials(scene, domain, F):
    """The materials of a scene on its domain, set into F's coefficients; a
    permeability that is not positive is a SceneError naming its key."""
    cells = domain.regions
    top = derive_parameters(scene)
    regions = [derive_parameters(scene, scene.regions[name]) for name in cells.names]
    every = [top] + regions
    for name, member in SCALARS:
        table = np.array([getattr(p, member) for p in every])
        _per_cell(F[name], 1, lambda c, x, table=table: table[cells.region[c] + 1])
    if scene.flow:
        agree_on_error(_set_resistivity(F["resistivity"], scene, cells, domain.dim), domain.mesh.comm)
    return Materials(top, regions, cells)


def check_materials(scene, domain):
    """What make_materials refuses, for `check`: the permeabilities evaluated
    cell by cell as a run evaluates them (collective; raises SceneError)."""
    if scene.flow:
        R = fem.Function(fem.TensorFunctionSpace(domain.mesh, ("DG", 0)))
        agree_on_error(_set_resistivity(R, scene, domain.regions, domain.dim), domain.mesh.comm)


def on(F, name, Q):
    """The values of coefficient `name` in the DOF order of the DG0 space Q."""
    f = fem.Function(Q)
    f.interpolate(F[name])
    return f.x.array.copy()
