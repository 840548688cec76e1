"""A scene: one TOML file that says what to simulate (docs/user-guide.md, "Scene reference").

Mirrors cpp/scene/scene.cpp key by key: the same defaults, the same checks in the
same order, and the same one-line messages `<file>: <key>: <message>`; the
choices are read into the enums of input.py, the tables by section.py's
Section. Tables are read in sorted key order, as toml++ (a sorted map) does,
so the order of the boundaries is the same.
"""
import bisect
import math
import os
import re
import tomllib
from dataclasses import dataclass, field
from typing import Optional

from mpi4py import MPI

from .expression import CONSTANTS, FUNCTIONS, VARIABLES, Expression, ExpressionError
from .input import (Acceleration, CouplingScheme, FaultFlow, LChoice, MeshType, ReferenceSolution, SceneError,
                    SolverChoice, TimeScheme, name_of)
from .section import Section, apply_override, identifiers, substitute_names

MAX_STEPS = 1000000  # at most this many (fine) time steps: a larger count is refused


def agree_on_error(message, comm):
    """Bad input found on some ranks only: every rank raises SceneError with
    the message of the lowest rank that found one, so that no rank is left
    waiting in a collective call (cpp/scene/scene.h). Collective."""
    owner = comm.allreduce(comm.rank if message else comm.size, op=MPI.MIN)
    if owner < comm.size:
        raise SceneError(comm.bcast(message, root=owner))


# ---- the scene, as cpp/scene/scene.h ------------------------------------------------

@dataclass
class MeshSpec:
    type: MeshType = MeshType.rectangle
    lower: list = field(default_factory=list)
    upper: list = field(default_factory=list)
    cells: list = field(default_factory=list)
    file: str = ""
    dimension: int = 2
    refine: int = 0  # uniform refinements of a gmsh mesh (nested: each halves h)


@dataclass
class FrictionSpec:
    """Friction on a contact (a foundation, or a fault's two faces): the
    tangential traction |t_T| <= cohesion + friction t_N (Coulomb, t_N the
    contact's normal traction, an effective stress where the faces carry a
    fluid pressure), or <= tresca, a given bound. Frictionless by default."""
    friction: float = 0.0
    cohesion: float = 0.0
    tresca: Optional[float] = None


@dataclass
class ContactSpec:
    """u.nu_F <= gap at the nodes of the boundary, nu_F the foundation's
    outward normal (from the body into the foundation), a constant vector or
    expressions of x, y, z (a curved foundation), normalised at each node."""
    gap: Expression
    normal: list
    friction: FrictionSpec = field(default_factory=FrictionSpec)


@dataclass
class BoundarySpec:
    mechanics: str = "traction_free"  # or "displacement", "traction", "contact" (which may carry a traction)
    displacement: list = field(default_factory=lambda: [None, None, None])
    traction: list = field(default_factory=list)
    contact: Optional[ContactSpec] = None
    pore_pressure_load: bool = False  # the pore pressure beside the face pushes on it (a fracture face)
    flow: str = "no_flow"             # or "pressure", "flux"
    pressure: Expression = field(default_factory=lambda: Expression(0.0))
    flux: Expression = field(default_factory=lambda: Expression(0.0))  # the outward normal Darcy flux z.n
    rate: Optional[Expression] = None  # or the total rate through the boundary (injection positive)


@dataclass
class MechanicsSpec:
    G: float = 0.0
    lmbda: float = 0.0
    body_force: Optional[list] = None
    # start from the displacement in equilibrium with the loads at t = 0
    # and the initial pressure (a geostatic initialisation), not u = 0
    initial_equilibrium: bool = False
    # A given pore pressure (of x, y, z, t) loading the skeleton in a scene
    # without [flow]: one-way coupling, for depletion studies. `alpha` is
    # its Biot coefficient (0 without it).
    pore_pressure: Optional[Expression] = None
    alpha: float = 0.0


@dataclass
class ClosureSpec:
    """Barton-Bandis closure of a conduit fault's hydraulic aperture under
    its effective normal stress s_n (docs/theory.md "Flow in a fault"): the
    closed fault's aperture w_r + V_m - V_m s_n/(K_ni V_m + s_n), V_m the
    largest closure (m), K_ni the initial normal stiffness (Pa/m)."""
    V_m: float = 0.0
    K_ni: float = 0.0


@dataclass
class FaultSpec:
    """A fault ([fault.NAME], issue 37): an interior physical group of a gmsh
    mesh whose two faces may open and slide. The scene reader reads and
    checks it; the split of the mesh along it and the contact of its faces
    use it (cpp/scene/scene.h)."""
    gap: Expression = field(default_factory=lambda: Expression(0.0))  # the initial normal aperture g0, of x, y, z
    pressure: Optional[Expression] = None  # the fluid pressure in the fault, pushing both faces apart (x, y, z, t)
    pore_pressure_load: bool = False       # the pore pressure beside each face pushes on it (not with pressure)
    flow: FaultFlow = FaultFlow.transparent
    # d numbers: the hint that orients the fault's normal; its + side is the
    # side the normal points into.
    normal: list = field(default_factory=list)
    friction: FrictionSpec = field(default_factory=FrictionSpec)
    # flow = "conduit": the hydraulic aperture w_h of the closed fault (m), and
    # the permeability across each face's half aperture (inf: the rock's
    # pressure at a face is the fault's)
    residual_aperture: float = 0.0
    normal_permeability: float = math.inf
    # flow = "conduit" in a scene with mechanics: the closed aperture's
    # Barton-Bandis closure (None: w_r at any stress)
    closure: Optional["ClosureSpec"] = None


@dataclass
class FlowSpec:
    M: float = math.inf
    c_f: float = 0.0
    phi0: float = 0.0
    mu_f: float = 1.0
    permeability: Optional[Expression] = None
    permeability_tensor: Optional[list] = None  # row-major d x d
    rho_f: Optional[float] = None
    gravity: Optional[list] = None
    source: Optional[Expression] = None
    initial_pressure: Expression = field(default_factory=lambda: Expression(0.0))

    def storage(self):
        """S = 1/M + c_f phi0 (alg. "Parameters")."""
        return 1.0 / self.M + self.c_f * self.phi0


@dataclass
class CouplingSpec:
    alpha: float = 1.0
    scheme: CouplingScheme = CouplingScheme.fixed_stress
    q: int = 1                  # 1 with q = "auto" (the first window's)
    # coupling.q = "auto" (window_control.py): each window's q, at most
    # q_max, from the predicted relative change of the displacement over
    # the window, at most q_tolerance.
    q_auto: bool = False
    q_max: int = 16
    q_tolerance: float = 1e-2
    L_choice: LChoice = LChoice.paper
    L_number: float = 0.0  # L_choice = number
    tolerance: float = 1e-8
    max_iterations: int = 100
    acceleration: Acceleration = Acceleration.none  # Anderson's keeps `depth` differences
    depth: int = 8

    def multirate(self):
        """q flow steps per mechanics step (either multirate scheme)."""
        return self.scheme in (CouplingScheme.multirate, CouplingScheme.multirate_two_pass)


@dataclass
class ReferenceSpec:
    solution: ReferenceSolution = ReferenceSolution.terzaghi
    load: float = 0.0   # terzaghi: the compressive traction on the top
    height: float = 0.0  # terzaghi: h
    force: float = 0.0  # mandel: F (2F on the full specimen, per unit thickness)
    plate: str = ""     # mandel: the boundary (y = b) carrying the rigid plate


@dataclass
class AdaptiveSpec:
    """time.adaptive: steps chosen by a local error estimate
    (time/step_control.py); time.dt is the first step."""
    tolerance: float = 0.0  # of the error per unit step, relative to the field's largest norm
    dt_min: float = 0.0
    dt_max: float = 0.0


@dataclass
class SolverSpec:
    """How each system is solved. PETSc options of a system's prefix override."""
    flow: SolverChoice = SolverChoice.automatic
    mechanics: SolverChoice = SolverChoice.automatic
    monolithic: SolverChoice = SolverChoice.automatic
    inexact_coupling: bool = True  # iterative solves only as accurate as the coupling increment needs


@dataclass
class WellSpec:
    """A point source or sink (2D) or a vertical line segment (3D); injection positive."""
    position: list                 # (x, y) of the point (2D) or of the vertical segment (3D)
    rate: Expression               # the total volumetric rate, a function of t
    bottom: float = 0.0            # the segment's z range (3D)
    top: float = 0.0
    fault: str = ""                # a conduit fault the well injects into (where it meets it), or the rock


@dataclass
class RegionSpec:
    """A material region: the cells of a gmsh physical group of cells, or
    those whose midpoint satisfies `where`, whose physics are the scene's own
    with some material values replaced (cpp/scene/scene.h)."""
    where: Optional[Expression] = None
    mechanics: Optional[MechanicsSpec] = None  # the scene's [mechanics] with the region's moduli, body_force
    body_force: bool = False                   # the region gives its own body force
    flow: Optional[FlowSpec] = None            # the scene's [flow] with the region's M, c_f, phi0, permeability
    alpha: float = 0.0                         # the scene's alpha or the region's


@dataclass
class Scene:
    file: str = ""
    name: str = ""
    description: str = ""
    mesh: MeshSpec = field(default_factory=MeshSpec)
    boundaries: dict = field(default_factory=dict)  # sorted by name
    wells: dict = field(default_factory=dict)       # sorted by name
    regions: dict = field(default_factory=dict)     # sorted by name; cells in none take the top-level values
    faults: dict = field(default_factory=dict)      # sorted by name
    mechanics: Optional[MechanicsSpec] = None
    flow: Optional[FlowSpec] = None
    coupling: Optional[CouplingSpec] = None
    end_time: float = 0.0
    dt: float = 0.0
    growth: float = 1.0  # time.growth: dt_k = dt growth^(k-1)
    retry: int = 0       # time.retry: a failed step is retried with halved steps up to this many times
    time_scheme: TimeScheme = TimeScheme.backward_euler  # time.scheme
    adaptive: Optional[AdaptiveSpec] = None  # time.adaptive
    write_xdmf: bool = True
    # output.times or output.every (and time.end): the times written after
    # t = 0; empty: every step.
    output_times: list = field(default_factory=list)
    checkpoint_every: int = 0  # output.checkpoint_every: steps between checkpoints, 0 none
    progress_interval: float = 10.0  # output.progress_interval: seconds between lines within a step
    reference: Optional[ReferenceSpec] = None
    solver: SolverSpec = field(default_factory=SolverSpec)

    def cellwise_body_force(self):
        """Some region gives its own body force: the body force is applied
        cell by cell (each cell its material's), not interpolated at the nodes."""
        return any(r.body_force for r in self.regions.values())

    def has_contact(self):
        """A contact boundary, or a fault (whose faces are a contact pair)."""
        return any(b.contact for b in self.boundaries.values()) or bool(self.faults)

    def times(self):
        """t_0 = 0, t_1, ..., t_N = end_time (fine steps) of fixed or growing
        steps (adaptive steps are planned by time/time_grid.py)."""
        if self.growth == 1.0:  # whole multiples of dt, so every scheme writes the same times
            return [0.0] + [k * self.dt for k in range(1, int(round(self.end_time / self.dt)) + 1)]
        t, step = [0.0], self.dt  # dt_k = dt growth^(k-1); the last step ends at time.end
        # Stops one past the limit, which read_scene then refuses.
        while t[-1] < self.end_time * (1 - 1e-12) and len(t) <= MAX_STEPS + 1:
            t.append(min(t[-1] + step, self.end_time))
            step *= self.growth
        return t

    def stops(self):
        """The times a step must land on: the output times and time.end."""
        return self.output_times or [self.end_time]

    def is_output_time(self, t):
        """Whether t is one of the output times (every t with no output.times)."""
        return not self.output_times or any(abs(s - t) <= 1e-9 * self.end_time for s in self.output_times)

    def num_steps(self):
        if self.growth == 1.0:
            return int(round(self.end_time / self.dt))
        return len(self.times()) - 1


def builtin_boundary_names(d):
    return ["left", "right", "bottom", "top"] if d == 2 else \
        ["left", "right", "front", "back", "bottom", "top"]


# ---- reading -------------------------------------------------------------------

def _read_mesh(s, scene_file):
    m = MeshSpec(type=s.choice("type", MeshType))
    if m.type in (MeshType.rectangle, MeshType.box):
        d = 2 if m.type == MeshType.rectangle else 3
        m.dimension = d
        m.lower = s.number_vector("lower", d) if s.has("lower") else [0.0] * d
        m.upper = s.number_vector("upper", d)
        n = s.number_vector("cells", d)
        for i in range(d):
            if m.upper[i] <= m.lower[i]:
                s.fail("upper", "must be above mesh.lower in every direction")
            if n[i] < 1 or n[i] != math.floor(n[i]):
                s.fail("cells", "must be positive integers")
            m.cells.append(int(n[i]))
        # Refused before any allocation (cpp/scene/scene.cpp): about 4 kB per
        # triangle and 25 kB per tetrahedron measured with direct solvers.
        simplices = (4.0 if d == 2 else 6.0) * math.prod(n)
        need = simplices * (4e3 if d == 2 else 25e3)
        have = os.sysconf("SC_PHYS_PAGES") * os.sysconf("SC_PAGE_SIZE")
        if have > 0 and need > have:
            s.fail("cells", f"{simplices:.2g} cells need about {need / 1e9:.2g} GB of memory; "
                   f"this machine has {have / 1e9:.2g} GB")
    else:
        name = s.string("file")
        # Mesh files are looked up next to the scene, then in meshes/.
        here = os.path.dirname(scene_file)
        for candidate in (os.path.join(here, name), os.path.join(here, "..", "meshes", name), name):
            if os.path.exists(candidate):
                m.file = os.path.normpath(candidate)
                break
        if not m.file:
            s.fail("file", "mesh file not found: " + name)
        m.dimension = s.integer("dimension", 2)
        if m.dimension not in (2, 3):
            s.fail("dimension", "must be 2 or 3")
        # Each refinement splits every simplex into 2^d: nested meshes, as
        # the studies' references need (tools/study.py maps nodes by position).
        m.refine = s.integer("refine", 0)
        if not 0 <= m.refine <= 6:
            s.fail("refine", "must be an integer in [0, 6]")
    s.finish()
    return m


def _read_friction(s):
    """friction, cohesion or tresca of a contact table or a fault (FrictionSpec)."""
    f = FrictionSpec(friction=s.number("friction", 0.0), cohesion=s.number("cohesion", 0.0))
    if not (f.friction >= 0 and math.isfinite(f.friction)):
        s.fail("friction", "must be a finite number >= 0 (the Coulomb coefficient)")
    if not (f.cohesion >= 0 and math.isfinite(f.cohesion)):
        s.fail("cohesion", "must be a finite number >= 0 (Pa)")
    if s.has("tresca"):
        if s.has("friction") or s.has("cohesion"):
            s.fail("tresca", "give tresca (a given bound) or friction and cohesion (Coulomb), not both")
        f.tresca = s.number("tresca")
        if not (f.tresca >= 0 and math.isfinite(f.tresca)):
            s.fail("tresca", "must be a finite number >= 0 (Pa)")
    return f


def _read_contact(c, d):
    """contact = { gap = .., normal = [..], friction.. }: the foundation of a
    contact boundary."""
    gap = c.expression("gap")
    if gap is None:
        c.fail("gap", "missing (the gap g_a to the foundation)")
    if gap.depends_on_time:
        c.fail("gap", "must not depend on t")
    normal = c.expression_vector("normal", d)
    if any(n.depends_on_time for n in normal):
        c.fail("normal", "must not depend on t")
    # A normal that varies in space is checked at every contact node.
    if all(n.is_constant for n in normal):
        length = sum(n(0, 0, 0, 0) ** 2 for n in normal)
        if not (length > 0 and math.isfinite(length)):
            c.fail("normal", "must be a non-zero finite vector")
    if gap.is_constant and gap(0, 0, 0, 0) < 0:
        c.fail("gap", "must be >= 0")
    friction = _read_friction(c)
    c.finish()
    return ContactSpec(gap, normal, friction)


def _read_boundary(s, d):
    b = BoundarySpec()
    # A traction may load a contact boundary (the fluid pressure on an open
    # fracture face); otherwise the mechanics conditions exclude each other.
    count = sum(s.has(k) for k in ("clamp", "displacement", "traction", "contact"))
    if count > 1 and not (count == 2 and s.has("traction") and s.has("contact")):
        s.fail("clamp", "give at most one of clamp, displacement, traction, contact (or traction with contact)")
    if s.has("clamp"):
        if not s.boolean("clamp", False):
            s.fail("clamp", "must be true when given")
        b.mechanics = "displacement"
        b.displacement = [Expression(0.0) if i < d else None for i in range(3)]
    if s.has("displacement"):
        b.mechanics = "displacement"
        c = s.section("displacement", True)
        b.displacement = [c.expression(n) if i < d else None for i, n in enumerate("xyz")]
        c.finish()
        if not any(b.displacement):
            s.fail("displacement", "give at least one component (x, y or z)")
    if s.has("traction"):
        b.mechanics = "traction"
        b.traction = s.expression_vector("traction", d)
    if s.has("contact"):
        b.mechanics = "contact"
        b.contact = _read_contact(s.section("contact", True), d)
    for key in ("friction", "cohesion", "tresca"):
        if s.has(key):
            s.fail(key, f"acts on a contact: give it in contact = {{ .., {key} = .. }}")
    b.pore_pressure_load = s.boolean("pore_pressure_load", False)
    if b.pore_pressure_load and not b.contact:
        s.fail("pore_pressure_load", "loads a contact boundary only (the face of a fracture)")

    if s.has("pressure") + s.has("flux") + s.has("rate") > 1:
        s.fail("rate" if s.has("rate") else "flux", "give at most one of pressure, flux, rate")
    p = s.expression("pressure")
    if p is not None:
        b.flow, b.pressure = "pressure", p
    f = s.expression("flux")
    if f is not None:
        b.flow, b.flux = "flux", f
    r = s.expression("rate")
    if r is not None:
        if r.depends_on_space:
            s.fail("rate", "the total rate through the boundary depends on t only (use flux for one that varies "
                   "along it)")
        b.flow, b.rate = "flux", r
    s.finish()
    return b


def _positive(s, key, value):
    if not (value > 0) or not math.isfinite(value):
        s.fail(key, "must be a positive finite number")


def _read_given_pore_pressure(s, m):
    """mechanics.pore_pressure and its Biot coefficient mechanics.alpha: a
    pore pressure given as an expression loads the skeleton (one-way
    coupling); whether the scene may have one is _read_physics's to say."""
    m.pore_pressure = s.expression("pore_pressure")
    if m.pore_pressure is not None and not s.has("alpha"):
        s.fail("alpha", "missing (the Biot coefficient of mechanics.pore_pressure)")
    if m.pore_pressure is None and s.has("alpha"):
        s.fail("alpha", "needs mechanics.pore_pressure (a coupled scene gives coupling.alpha)")
    m.alpha = s.number("alpha", 0.0)
    if m.pore_pressure is not None and not 0 < m.alpha <= 1:
        s.fail("alpha", "the Biot coefficient must lie in (0, 1]")


def _read_mechanics(s, d):
    m = MechanicsSpec()
    e_nu = s.has("E") or s.has("nu")
    lame = s.has("G") or s.has("lambda")
    if e_nu and lame:
        s.fail("E", "give either E and nu, or G and lambda, not both")
    if not e_nu and not lame:
        s.fail("E", "missing (give E and nu, or G and lambda)")
    if e_nu:
        E, nu = s.number("E"), s.number("nu")
        _positive(s, "E", E)
        if not (-1.0 < nu < 0.5):
            s.fail("nu", "must lie in (-1, 0.5); nu >= 0.5 is an incompressible skeleton")
        m.G = E / (2 * (1 + nu))
        m.lmbda = E * nu / ((1 + nu) * (1 - 2 * nu))
    else:
        m.G, m.lmbda = s.number("G"), s.number("lambda")
        _positive(s, "G", m.G)
        if not math.isfinite(m.lmbda) or m.lmbda + 2 * m.G / d <= 0:
            s.fail("lambda", "must be finite with K_dr = lambda + 2G/d > 0")
    if s.has("body_force"):
        m.body_force = s.expression_vector("body_force", d)
    m.initial_equilibrium = s.boolean("initial_equilibrium", False)
    _read_given_pore_pressure(s, m)
    s.finish()
    return m


def _spd(K, d):
    """Symmetric with positive leading minors."""
    sym = all(abs(K[i * d + j] - K[j * d + i]) <= 1e-12 * abs(K[i * d + i]) for i in range(d) for j in range(d))
    m1, m2 = K[0], K[0] * K[d + 1] - K[1] * K[d]
    m3 = 1.0
    if d == 3:
        m3 = (K[0] * (K[4] * K[8] - K[5] * K[7]) - K[1] * (K[3] * K[8] - K[5] * K[6])
              + K[2] * (K[3] * K[7] - K[4] * K[6]))
    return sym and m1 > 0 and m2 > 0 and m3 > 0


def _read_flow(s, d):
    f = FlowSpec()
    f.M = s.number("M", math.inf)
    if not (f.M > 0):
        s.fail("M", "must be positive (inf for incompressible grains)")
    f.c_f = s.number("c_f", 0.0)
    if not (f.c_f >= 0) or not math.isfinite(f.c_f):
        s.fail("c_f", "must be >= 0")
    f.phi0 = s.number("phi0", 0.0)
    if not (0 <= f.phi0 <= 1):
        s.fail("phi0", "must lie in [0, 1]")
    f.mu_f = s.number("mu_f")
    _positive(s, "mu_f", f.mu_f)

    k = s.node("permeability")
    if k is None:
        s.fail("permeability", "missing")
    if isinstance(k, list):
        K = []
        for row in k:
            if not isinstance(row, list) or len(row) != d:
                s.fail("permeability", f"a tensor must be {d} rows of {d} numbers")
            for e in row:
                if not Section.is_number(e):
                    s.fail("permeability", "tensor entries must be numbers")
                K.append(float(e))
        if len(K) != d * d:
            s.fail("permeability", f"a tensor must have {d} rows")
        if not _spd(K, d):
            s.fail("permeability", "the tensor must be symmetric positive definite")
        f.permeability_tensor = K
    else:
        f.permeability = s.to_expression(k, "permeability")
        if f.permeability.is_constant:
            _positive(s, "permeability", f.permeability(0, 0, 0, 0))
        if f.permeability.depends_on_time:
            s.fail("permeability", "must not depend on t")

    if s.has("gravity") != s.has("rho_f"):
        s.fail("rho_f" if s.has("gravity") else "gravity", "gravity needs both rho_f and gravity")
    if s.has("gravity"):
        f.rho_f = s.number("rho_f")
        _positive(s, "rho_f", f.rho_f)
        f.gravity = s.number_vector("gravity", d)
    f.source = s.expression("source")
    f.initial_pressure = s.expression("initial_pressure") or Expression(0.0)
    if f.initial_pressure.depends_on_time:
        s.fail("initial_pressure", "must not depend on t")
    s.finish()
    return f


def _read_window_steps(s, c):
    """coupling.q: a positive integer, or "auto" (window_control.py) with
    the largest q (q_max) and the tolerance of the predicted relative change
    of the displacement over a window (q_tolerance)."""
    c.q_auto = s.node("q") == "auto"
    c.q = 1 if c.q_auto else s.integer("q", 1)
    if c.q < 1:
        s.fail("q", 'must be a positive integer or "auto"')
    if not c.multirate() and (c.q != 1 or c.q_auto):
        s.fail("q", ('q = "auto"' if c.q_auto else "q > 1") + ' needs scheme = "multirate" or "multirate-two-pass"')
    if not c.q_auto:
        for key in ("q_max", "q_tolerance"):
            if s.has(key):
                s.fail(key, 'needs q = "auto"')
        return
    c.q_max = s.integer("q_max", 16)
    if not 1 <= c.q_max <= 1024:
        s.fail("q_max", "must be an integer from 1 to 1024")
    c.q_tolerance = s.number("q_tolerance", 1e-2)
    if not 0 < c.q_tolerance < 1:
        s.fail("q_tolerance", "must lie in (0, 1)")


def _read_coupling(s, mech, flow):
    c = CouplingSpec()
    c.alpha = s.number("alpha")
    if not (0 <= c.alpha <= 1):
        s.fail("alpha", "the Biot coefficient must lie in [0, 1]")
    c.scheme = s.choice("scheme", CouplingScheme, CouplingScheme.fixed_stress)
    # The second pass is a flow step without L: with S = 0 its matrix has a
    # zero pressure block, singular wherever no pressure is prescribed.
    if c.scheme == CouplingScheme.multirate_two_pass and not flow.storage() > 0:
        s.fail("scheme", '"multirate-two-pass" needs a storage coefficient S = 1/M + c_f phi0 > 0')
    _read_window_steps(s, c)

    L = s.node("L")
    if L is None:
        c.L_choice = LChoice.paper
    elif Section.is_number(L):
        c.L_choice, c.L_number = LChoice.number, float(L)
        if not (c.L_number >= 0) or not math.isfinite(c.L_number):
            s.fail("L", "must be >= 0")
    elif isinstance(L, str) and L in ("paper", "kdr", "half-kdr"):
        c.L_choice = LChoice(L)
    else:
        s.fail("L", 'must be "paper", "kdr", "half-kdr" or a number')
    if c.L_choice == LChoice.paper and not (mech.lmbda > 0):
        s.fail("L", '"paper" (alpha^2/lambda) needs lambda > 0; use "kdr"')

    c.tolerance = s.number("tolerance", 1e-8)
    if not (0 < c.tolerance < 1):
        s.fail("tolerance", "must lie in (0, 1)")
    c.max_iterations = s.integer("max_iterations", 100)
    if c.max_iterations < 1:
        s.fail("max_iterations", "must be a positive integer")
    c.acceleration = s.choice("acceleration", Acceleration, Acceleration.none)
    if c.acceleration != Acceleration.none and c.scheme == CouplingScheme.monolithic:
        s.fail("acceleration", "accelerates the split; the monolithic scheme has no coupling iteration")
    c.depth = s.integer("depth", 8)
    if not 1 <= c.depth <= 50:
        s.fail("depth", "must be an integer from 1 to 50")
    s.finish()
    return c


def read_scene(file, overrides=()):
    """Reads and validates a scene; `overrides` are "key.path=value" strings."""
    root = _parse_scene(file, overrides)
    scene = Scene(file=file)
    top = Section(root, "", file)
    top.set_names(_read_names(top.section("expressions", False)))
    _read_meta(top, scene)
    scene.mesh = _read_mesh(top.section("mesh", True), file)
    top.set_axes(scene.mesh.dimension)
    _read_physics(top, scene)
    _read_time(top, scene)
    _read_output(top.section("output", False), scene)
    _read_solver(top.section("solver", False), scene.solver)
    _read_boundaries(top.section("boundary", False), scene)
    _read_faults(top.section("fault", False), scene)
    _read_wells(top.section("well", False), scene)
    _read_regions(top.section("region", False), root, scene)
    if top.has("reference"):
        _read_reference(top.section("reference", True), scene)
    top.finish()
    return scene


def _parse_scene(file, overrides):
    """The scene file as a dict, with the --set overrides applied."""
    if not os.path.isfile(file):
        raise SceneError(f"{file}: scene file not found")
    try:
        with open(file, "rb") as f:
            root = tomllib.load(f)
    except tomllib.TOMLDecodeError as e:
        m = re.search(r"\(at line (\d+), column \d+\)", str(e))
        line, description = m.group(1) if m else "1", re.sub(r" \(at .*\)$", "", str(e))
        raise SceneError(f"{file}:{line}: invalid TOML: {description}") from None
    for o in overrides:
        apply_override(root, o, file)
    return root


# The identifiers an expression already knows (expression.py: variables,
# constants and functions), which no name may take.
_RESERVED = set(VARIABLES) | set(CONSTANTS) | set(FUNCTIONS)


def _resolve_name(name, given, resolved, path, s):
    """The text of `name` with the names it uses substituted, resolving them
    first (depth first); `path` holds the names being resolved, so that a
    cycle is refused naming it (C++'s resolve_name)."""
    if name in resolved:
        return resolved[name]
    if name in path:
        cycle = " -> ".join(path[path.index(name):] + [name])
        s.fail(path[0], f"the names refer to one another in a cycle ({cycle})")
    path.append(name)
    for used in identifiers(given[name]):
        if used in given:
            _resolve_name(used, given, resolved, path, s)
    path.pop()
    resolved[name] = substitute_names(given[name], resolved)
    return resolved[name]


def _read_names(s):
    """[expressions]: names for numbers and expressions of x, y, z, t, each
    usable in every expression of the scene and in the other names' (in any
    order, without a cycle); each is parsed as every expression is."""
    given, resolved = {}, {}
    for name in s.keys():
        if identifiers(name) != [name] or name in _RESERVED:
            s.fail(name, "not a name: a letter or _ then letters, digits or _, none of x, y, z, t, pi and the "
                   "functions of an expression")
        n = s.node(name)
        if s.is_number(n):
            given[name] = Expression(float(n)).text
        elif isinstance(n, str):
            given[name] = n
        else:
            s.fail(name, "must be a number or an expression string")
    for name, text in sorted(given.items()):
        _resolve_name(name, given, resolved, [], s)
        try:
            Expression(resolved[name], text)
        except ExpressionError as e:
            s.fail(name, str(e))
    s.finish()
    return resolved


def _read_meta(top, scene):
    """[scene]: the name (the file's stem by default) and description."""
    meta = top.section("scene", False)
    scene.name = meta.string("name", os.path.splitext(os.path.basename(scene.file))[0])
    scene.description = meta.string("description", "")
    meta.finish()


def _read_physics(top, scene):
    """[mechanics], [flow] and, when both are there, [coupling]."""
    d = scene.mesh.dimension
    if top.has("mechanics"):
        scene.mechanics = _read_mechanics(top.section("mechanics", True), d)
    if top.has("flow"):
        scene.flow = _read_flow(top.section("flow", True), d)
    if not scene.mechanics and not scene.flow:
        top.fail("mechanics", "a scene needs a [mechanics] or a [flow] table (or both)")
    if scene.flow and scene.mechanics and scene.mechanics.pore_pressure is not None:
        top.fail("mechanics.pore_pressure", "a given pore pressure is for a scene without [flow] (here the flow "
                 "computes it)")
    if scene.mechanics and scene.flow:
        scene.coupling = _read_coupling(top.section("coupling", True), scene.mechanics, scene.flow)
    elif top.has("coupling"):
        top.fail("coupling", "only a scene with both [mechanics] and [flow] is coupled")


def _read_adaptive(time, scene):
    """time.adaptive: the tolerance and the bounds of the step (the first step
    is time.dt)."""
    if not time.has("adaptive"):
        return None
    a = time.section("adaptive", False)
    s = AdaptiveSpec()
    s.tolerance = a.number("tolerance")
    if not 0 < s.tolerance < 1:
        a.fail("tolerance", "must lie in (0, 1)")
    s.dt_min = a.number("dt_min", min(scene.dt, max(scene.dt / 1000, scene.end_time / MAX_STEPS)))
    s.dt_max = a.number("dt_max", scene.end_time)
    if not 0 < s.dt_min <= scene.dt:
        a.fail("dt_min", "must lie in (0, time.dt] (default time.dt / 1000)")
    if not s.dt_max >= scene.dt:
        a.fail("dt_max", "must be >= time.dt (default time.end)")
    if scene.end_time / s.dt_min > MAX_STEPS:
        a.fail("dt_min", f"time.end / dt_min is more than the limit of {MAX_STEPS} steps")
    a.finish()
    if scene.growth > 1.0:
        time.fail("adaptive", "adaptive steps and time.growth exclude each other")
    if scene.coupling and (scene.coupling.q != 1 or scene.coupling.q_auto):
        q = '"auto"' if scene.coupling.q_auto else scene.coupling.q
        time.fail("adaptive", f"adaptive steps need q = 1 (coupling.q is {q})")
    return s


def _check_step_count(time, scene):
    """Fixed steps: time.end must be a whole number of at most MAX_STEPS
    steps dt."""
    steps = scene.end_time / scene.dt
    if steps > MAX_STEPS:
        time.fail("dt", f"time.end / time.dt = {steps:.3g} steps, more than the limit of {MAX_STEPS}")
    if abs(steps - round(steps)) > 1e-9 * steps or round(steps) < 1:
        time.fail("dt", "time.end must be a whole number of steps dt")


def _read_time(top, scene):
    """[time]: the end, the first step, its growth or adaptation, the retries
    and the scheme; fixed steps must be whole, at most MAX_STEPS and, with
    q > 1, whole windows."""
    time = top.section("time", True)
    scene.end_time = time.number("end")
    scene.dt = time.number("dt")
    _positive(time, "dt", scene.dt)
    _positive(time, "end", scene.end_time)
    scene.growth = time.number("growth", 1.0)
    scene.retry = time.integer("retry", 0)
    if not 0 <= scene.retry <= 20:
        time.fail("retry", "must lie in [0, 20] (each retry halves the step)")
    if not (1.0 <= scene.growth <= 10.0):
        time.fail("growth", "must lie in [1, 10]")
    scene.time_scheme = time.choice("scheme", TimeScheme, TimeScheme.backward_euler)
    scene.adaptive = _read_adaptive(time, scene)
    if scene.adaptive:
        time.finish()
        return
    if scene.growth == 1.0:
        _check_step_count(time, scene)
    if scene.growth > 1.0 and scene.coupling and (scene.coupling.q != 1 or scene.coupling.q_auto):
        time.fail("growth", "growing time steps need q = 1")
    if scene.num_steps() > MAX_STEPS:
        time.fail("growth", f"more than {MAX_STEPS} time steps")
    time.finish()
    if scene.coupling and scene.num_steps() % scene.coupling.q != 0:
        top.fail("coupling.q", "the number of fine steps (time.end/time.dt) must be a multiple of q")


def _read_output_times(output, scene):
    """output.times or output.every: the times written, increasing, in
    (0, time.end], time.end added; with fixed or growing steps each must be
    the end of a step (of a window for q > 1)."""
    if output.has("times") and output.has("every"):
        output.fail("every", "give output.times or output.every, not both")
    end = scene.end_time
    slack = 1e-9 * end
    if output.has("times"):
        t = output.number_vector("times", 0)
        for i, ti in enumerate(t):
            if not (ti > 0 and ti <= end + slack and (i == 0 or ti > t[i - 1] + slack)):
                output.fail("times", "must increase strictly within (0, time.end]")
    elif output.has("every"):
        every = output.number("every")
        if not 0 < every <= end:
            output.fail("every", "must lie in (0, time.end]")
        t, k = [], 1
        while k * every <= end + slack:
            t.append(k * every)
            k += 1
    else:
        return []
    if not t or t[-1] < end - slack:
        t.append(end)
    t[-1] = end
    if scene.adaptive:
        return t
    run, q = scene.times(), scene.coupling.q if scene.coupling else 1
    for s in t:
        k = bisect.bisect_left(run, s - slack)
        if k == len(run) or abs(run[k] - s) > slack or k % q != 0:
            what = "window" if q > 1 else "step"
            output.fail("times" if output.has("times") else "every",
                        f"{s:.6g} is not the end of a {what} of the run (time.dt = {scene.dt:g}"
                        f"{f', q = {q}' if q > 1 else ''}); time.adaptive lands on any time")
    return t


def _read_output(output, scene):
    """[output]: XDMF on or off, the times written, the checkpoint interval
    (in steps) and the progress interval (seconds)."""
    scene.write_xdmf = output.boolean("xdmf", True)
    scene.output_times = _read_output_times(output, scene)
    scene.checkpoint_every = output.integer("checkpoint_every", 0)
    if scene.checkpoint_every < 0:
        output.fail("checkpoint_every", "must be >= 0 (0: no checkpoints)")
    scene.progress_interval = output.number("progress_interval", 10.0)
    _positive(output, "progress_interval", scene.progress_interval)
    output.finish()


def _read_solver(solver, choices):
    """[solver]: direct, iterative or auto for each system, and inexact coupling."""
    for key in ("flow", "mechanics", "monolithic"):
        setattr(choices, key, solver.choice(key, SolverChoice, SolverChoice.automatic))
    choices.inexact_coupling = solver.boolean("inexact_coupling", True)
    solver.finish()


def _read_boundaries(boundaries, scene):
    """[boundary.NAME]: built-in meshes know their boundaries' names; a gmsh
    mesh's are checked against its physical groups when the domain is made."""
    d = scene.mesh.dimension
    names = builtin_boundary_names(d)
    for name in boundaries.keys():
        if scene.mesh.type != MeshType.gmsh and name not in names:
            boundaries.fail(name, f"unknown boundary name (a {name_of(scene.mesh.type)} has {', '.join(names)})")
        b = _read_boundary(boundaries.section(name, True), d)
        if not scene.mechanics and b.mechanics != "traction_free":
            boundaries.fail(name, "mechanics boundary condition in a scene without [mechanics]")
        if not scene.flow and b.flow != "no_flow":
            boundaries.fail(name, "flow boundary condition in a scene without [flow]")
        if b.pore_pressure_load and not scene.coupling and not (scene.mechanics and scene.mechanics.pore_pressure):
            boundaries.fail(name + ".pore_pressure_load", "needs a pore pressure: a coupled scene, or "
                            "mechanics.pore_pressure")
        scene.boundaries[name] = b
    boundaries.finish()


def _read_wells(wells, scene):
    """[well.NAME]: position = [x, y], rate = expr of t; in 3D a vertical
    segment from bottom to top (z). Whether it lies in the mesh is checked
    when the domain is made."""
    for name in sorted(wells.keys()):
        s = wells.section(name, True)
        if not scene.flow:
            wells.fail(name, "a well in a scene without [flow]")
        position = s.number_vector("position", 2)
        bottom = top = 0.0
        if scene.mesh.dimension == 3:
            bottom, top = s.number("bottom"), s.number("top")
            if not top > bottom:
                s.fail("top", "must be above bottom (the well is the vertical segment from bottom to top)")
        rate = s.expression("rate")
        if rate is None:
            s.fail("rate", "missing (the volumetric rate, injection positive)")
        if rate.depends_on_space:
            s.fail("rate", "the rate of a well depends on t only")
        fault = s.string("fault", "")
        if fault and fault not in scene.faults:
            s.fail("fault", f'no fault "{fault}" in the scene ([fault.{fault}])')
        if fault and scene.faults[fault].flow != FaultFlow.conduit:
            s.fail("fault", f'fault.{fault} is no conduit (flow = "conduit"): a well injects into the rock or a '
                   "conduit fault")
        s.finish()
        scene.wells[name] = WellSpec(position, rate, bottom, top, fault)
    wells.finish()


_MECHANICS_KEYS = ("E", "nu", "G", "lambda", "body_force")
_FLOW_KEYS = ("M", "c_f", "phi0", "permeability")


def _region_physics(root, physics, region, keys):
    """A copy of the scene's table `physics` with the region's values of
    `keys` in place of its own; giving one of a pair of moduli drops the
    other pair from the copy (E, nu replace G, lambda)."""
    merged = dict(root[physics])
    if any(k in region for k in ("E", "nu")):
        merged.pop("G", None), merged.pop("lambda", None)
    if any(k in region for k in ("G", "lambda")):
        merged.pop("E", None), merged.pop("nu", None)
    merged.update({k: region[k] for k in keys if k in region})
    return merged


def _check_region_keys(s, scene):
    """Each key of a region is a material value of a physics the scene has."""
    for key in s.keys():
        mechanics, flow = key in _MECHANICS_KEYS, key in _FLOW_KEYS
        if key not in ("where", "alpha") and not mechanics and not flow:
            s.fail(key, "unknown key (a region may set where, E, nu, G, lambda, body_force, alpha, M, c_f, phi0, "
                   "permeability)")
        if (mechanics and not scene.mechanics) or (flow and not scene.flow) or (key == "alpha" and not scene.coupling):
            s.fail(key, "the scene has no [" + ("mechanics" if mechanics else "flow" if flow else "coupling")
                   + "] whose value a region could replace")
        s.node(key)


def _read_regions(regions, root, scene):
    """[region.NAME] (cpp/scene/scene.cpp read_regions): each region's physics
    are read by the readers of the scene's own tables, so errors name
    region.NAME.KEY; which cells it holds is settled with the domain."""
    d = scene.mesh.dimension
    for name in regions.keys():
        s = regions.section(name, True)
        _check_region_keys(s, scene)
        r = RegionSpec(where=s.expression("where"), body_force=s.has("body_force"))
        if r.where is not None and (r.where.depends_on_time or r.where.is_constant):
            s.fail("where", "must be an expression of x, y, z (the cell midpoints it selects)")
        if scene.mesh.type != MeshType.gmsh and r.where is None:
            s.fail("where", "missing (on a built-in mesh a region is the cells whose midpoint satisfies where)")
        if scene.mechanics:
            merged = _region_physics(root, "mechanics", s.table, _MECHANICS_KEYS)
            r.mechanics = _read_mechanics(regions.derived(merged, name), d)
        if scene.flow:
            merged = _region_physics(root, "flow", s.table, _FLOW_KEYS)
            r.flow = _read_flow(regions.derived(merged, name), d)
        if scene.coupling:
            r.alpha = s.number("alpha", scene.coupling.alpha)
            if not (0 <= r.alpha <= 1):
                s.fail("alpha", "the Biot coefficient must lie in [0, 1]")
            if scene.coupling.L_choice == LChoice.paper and not r.mechanics.lmbda > 0:
                s.fail("lambda", 'coupling.L = "paper" (alpha^2/lambda) needs lambda > 0; use "kdr"')
        elif r.mechanics:
            r.alpha = r.mechanics.alpha  # mechanics.pore_pressure's, which a region does not replace
        s.finish()
        scene.regions[name] = r
    regions.finish()


def _read_fault(s, scene):
    """fault.NAME: the gap, the fluid pressure in the fault or the pore
    pressure beside it, what the fault is to the flow, and the normal's hint."""
    f = FaultSpec(gap=s.expression("gap") or Expression(0.0))
    if f.gap.depends_on_time:
        s.fail("gap", "must not depend on t")
    f.pressure = s.expression("pressure")
    f.pore_pressure_load = s.boolean("pore_pressure_load", False)
    if f.pore_pressure_load and f.pressure is not None:
        s.fail("pore_pressure_load", "give pressure or pore_pressure_load, not both")
    if f.pore_pressure_load and not scene.flow and not (scene.mechanics and scene.mechanics.pore_pressure):
        s.fail("pore_pressure_load", "needs a pore pressure: [flow], or mechanics.pore_pressure")
    f.flow = s.choice("flow", FaultFlow, FaultFlow.transparent)
    if f.flow != FaultFlow.transparent and not scene.flow:
        s.fail("flow", f'"{name_of(f.flow)}" in a scene without [flow]')
    if f.flow == FaultFlow.pressure and f.pressure is None:
        s.fail("pressure", 'missing (flow = "pressure" holds the fault at this pressure)')
    if f.flow == FaultFlow.conduit:
        # A conduit's faces carry its own fluid pressure p_f: any other
        # pressure on them would be a second, contradictory one.
        if f.pressure is not None:
            s.fail("pressure", 'not with flow = "conduit": the fault\'s own fluid pressure p_f pushes on its faces')
        if f.pore_pressure_load:
            s.fail("pore_pressure_load", 'not with flow = "conduit": the fault\'s own fluid pressure p_f pushes on '
                   "its faces, not the rock's")
        _read_conduit(s, scene, f)
    d = scene.mesh.dimension
    f.normal = s.number_vector("normal", d) if s.has("normal") else [0.0] * (d - 1) + [1.0]
    length = sum(n * n for n in f.normal)
    if not (length > 0 and math.isfinite(length)):
        s.fail("normal", "must be a non-zero finite vector")
    f.friction = _read_friction(s)
    s.finish()
    return f


def _read_conduit(s, scene, f):
    """A conduit fault's hydraulic keys (docs/user-guide.md, "Flow in a
    fault"): its aperture where closed, w_r > 0, the permeability across
    its faces, k_n > 0 or "inf", and the closure of its aperture."""
    if (scene.coupling and scene.coupling.scheme == CouplingScheme.monolithic
            and scene.solver.monolithic == SolverChoice.iterative):
        s.fail("flow", '"conduit" with solver.monolithic = "iterative": the monolithic system with the fault\'s '
               'pressure is solved directly ("direct" or "auto")')
    if scene.time_scheme == TimeScheme.bdf2:
        s.fail("flow", '"conduit" with time.scheme = "bdf2": the fault\'s storage is backward Euler only yet '
               "(issue 39)")
    f.residual_aperture = s.number("residual_aperture")
    if not (f.residual_aperture > 0 and math.isfinite(f.residual_aperture)):
        s.fail("residual_aperture", "must be a finite number > 0 (m)")
    if s.has("normal_permeability") and s.table["normal_permeability"] == "inf":
        s.used.add("normal_permeability")
    else:
        f.normal_permeability = s.number("normal_permeability", math.inf)
        if not f.normal_permeability > 0:
            s.fail("normal_permeability", 'must be > 0 (m^2) or "inf"')
    if s.has("closure") and not scene.mechanics:
        s.fail("closure", "needs [mechanics]: the closed aperture follows the fault's normal stress")
    if s.has("closure"):
        f.closure = _read_closure(s.section("closure", True))


def _read_closure(c):
    """closure = { V_m = .., K_ni = .. }: the Barton-Bandis closure of a
    conduit fault, whose normal stress the mechanics gives."""
    closure = ClosureSpec(V_m=c.number("V_m"))
    if not (closure.V_m > 0 and math.isfinite(closure.V_m)):
        c.fail("V_m", "must be a finite number > 0 (m, the largest closure)")
    closure.K_ni = c.number("K_ni")
    if not (closure.K_ni > 0 and math.isfinite(closure.K_ni)):
        c.fail("K_ni", "must be a finite number > 0 (Pa/m, the initial normal stiffness)")
    c.finish()
    return closure


def _read_faults(faults, scene):
    """[fault.NAME]: faults lie inside a gmsh mesh, on groups that are not
    boundaries. That NAME is an interior group of the mesh, and the gap
    >= 0 at its nodes, are checked where the mesh is split along it."""
    for name in faults.keys():
        s = faults.section(name, True)
        if scene.mesh.type != MeshType.gmsh:
            faults.fail(name, 'a fault is an interior physical group of a gmsh mesh (mesh.type = "gmsh")')
        if name in scene.boundaries:
            faults.fail(name, f"also given as [boundary.{name}]: a physical group is a boundary or a fault, not both")
        scene.faults[name] = _read_fault(s, scene)
    faults.finish()


def _check_mandel_plate(r, scene, ref):
    """Mandel's rigid frictionless plate goes on the boundary ref.plate,
    which must be free: set-up imposes the exact u_y there
    (diagnostics/closed_form.py, with_mandel_plate)."""
    if scene.mesh.lower[0] != 0.0 or scene.mesh.lower[1] != 0.0:
        r.fail("solution", "mandel needs mesh.lower = [0, 0] (the quarter specimen)")
    plate = scene.boundaries.get(ref.plate)
    if plate is None or plate.mechanics != "traction_free":
        r.fail("plate", "must name a boundary with no mechanics condition of its own")


def _read_reference(r, scene):
    """[reference]: the closed form the run is compared with ("none" switches
    the comparison of a reference scene off, e.g. from --set)."""
    solution = r.string("solution")
    if solution not in ("terzaghi", "mandel", "none"):
        r.fail("solution", 'must be "terzaghi", "mandel" or "none"')
    if solution == "none":
        r.used.update(r.keys())
        r.finish()
        return
    ref = ReferenceSpec(solution=ReferenceSolution(solution))
    if not scene.coupling or scene.mesh.type != MeshType.rectangle:
        r.fail("solution", solution + " needs a coupled scene on a rectangle")
    if scene.flow.permeability is None or not scene.flow.permeability.is_constant:
        r.fail("solution", solution + " needs a constant scalar flow.permeability")
    if scene.regions:
        r.fail("solution", solution + " is the closed form of a homogeneous medium: the scene has regions")
    if ref.solution == ReferenceSolution.terzaghi:
        ref.load = r.number("load")
        ref.height = scene.mesh.upper[1] - scene.mesh.lower[1]
    else:
        ref.force = r.number("force")
        ref.plate = r.string("plate", "top")
        _check_mandel_plate(r, scene, ref)
    r.finish()
    scene.reference = ref
