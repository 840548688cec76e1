"""The scene's schema (cpp/scene/schema.h): what a scene says, table by table
(docs/user-guide.md, "Scene reference"), as the scene's readers fill it in
(scene.py reads a scene, the *_input.py the tables) and every stage of a run
reads it."""
import math
from dataclasses import dataclass, field
from typing import Optional

from .expression import Expression
from .input import (Acceleration, CouplingScheme, Fallback, FaultFlow, LChoice, MeshType, ReferenceSolution,
                    SolverChoice, TimeScheme)

MAX_STEPS = 1000000  # at most this many (fine) time steps: a larger count is refused


@dataclass
class MeshSpec:
    type: MeshType = MeshType.rectangle
    lower: list = field(default_factory=list)
    upper: list = field(default_factory=list)
    cells: list = field(default_factory=list)
    file: str = ""
    dimension: int = 2
    refine: int = 0  # uniform refinements of a gmsh mesh (nested: each halves h)
    size_factor: float = 1.0  # every size gmsh meshes a .geo with, times this (not nested)


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
    use it (cpp/scene/schema.h)."""
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
    # flow = "conduit": the fault's own tangential permeability k_f (m^2), its
    # transmissivity k_f w_h; 0: the cubic law's, w_h^3 / 12
    permeability: float = 0.0
    # flow = "conduit" in a scene with mechanics: the closed aperture's
    # Barton-Bandis closure (None: w_r at any stress)
    closure: Optional["ClosureSpec"] = None
    # The mesh size at the fault's tips (its edges inside the body, m; 0: the
    # mesh as drawn) and its growth per metre away from them: gmsh meshes a
    # .geo with at most tip_size + tip_grading * distance.
    tip_size: float = 0.0
    tip_grading: float = 0.5


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
    acceleration: Acceleration = Acceleration.automatic  # Anderson's keeps `depth` differences
    depth: int = 8
    fallback: Fallback = Fallback.none
    pin_cycles: bool = True  # a cycle of the split at a pair's kink is ended by pins (coupling/pins.py)

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


def default_cells_per_rank(dimension):
    """Below this many cells per rank, 15000 triangles or 2000 tetrahedra, a
    second rank costs a run more than it saves (docs/performance.md,
    "nineteenth session"; in 2D, where each rank makes every back-solve,
    "forty-second session"): a tetrahedron carries more work."""
    return 15000 if dimension == 2 else 2000


@dataclass
class SolverSpec:
    """How each system is solved. PETSc options of a system's prefix override."""
    flow: SolverChoice = SolverChoice.automatic
    mechanics: SolverChoice = SolverChoice.automatic
    monolithic: SolverChoice = SolverChoice.automatic
    inexact_coupling: bool = True  # iterative solves only as accurate as the coupling increment needs
    cells_per_rank: int = default_cells_per_rank(2)  # the fewest cells a rank works on (domain/working_ranks.py); 0: every rank


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
    with some material values replaced (cpp/scene/schema.h)."""
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
