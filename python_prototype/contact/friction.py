"""Friction as the VI's equations (theory.md, "Friction";
cpp/contact/friction.h): a frictional constraint's tangential rows of
F(x) = K x - b become
    F_T = R_T + P(theta) / s,   theta = -R_T s + c ds,
the residual R plus the trial force theta (t_T + c times the slip increment
since the step's start) projected on the disc |t| <= bound(t_N)
(contact_law.project_on_disc): F_T = c ds / s where the constraint sticks,
R_T + bound n / s where it slips, R_T where it is open. F is semismooth; its
generalised Jacobian replaces the tangential rows of K by combinations of
the constraint's own rows (friction_jacobian). One Newton solve decides
open, stick and slip (Hueber, Stadler and Wohlmuth 2008)."""
import dataclasses
from collections import defaultdict

from petsc4py import PETSc

from .contact_law import (ContactLaw, DiscProjection, on_foundation, project_on_disc, slip_bound,
                          slip_bound_slope)


@dataclasses.dataclass
class FrictionalConstraint:
    """A frictional constraint in the VI's numbering: the positions of its
    normal and d - 1 tangential unknowns, the side of its bound (sign:
    u.nu = sign x'), its gap and lumped measure, and its law."""
    normal: int = -1
    tangential: list = dataclasses.field(default_factory=lambda: [-1, -1])
    sign: float = 1.0
    gap: float = 0.0
    lumped: float = 0.0
    law: ContactLaw = dataclasses.field(default_factory=ContactLaw)


@dataclasses.dataclass
class FrictionPoint:
    """Where friction is evaluated: the VI's unknown X and residual
    R = K X - b (both in units of the displacement scale), the unknowns at
    the step's start (unscaled), the diagonal c of K, the scale and the
    number of tangents (d - 1)."""
    X: object
    R: object
    start: object
    stiffness: object
    scale: float
    tangents: int


@dataclasses.dataclass
class FrictionTerm:
    """Friction at one constraint: closed or not, its normal traction t_N
    (>= 0 pressing), its bound (a force: the law's times the lumped measure;
    0 when open), d bound / d t_N, its stiffness c (one for its tangents),
    its slip increment and the projection of its trial force."""
    closed: bool = False
    normal: float = 0.0
    bound: float = 0.0
    slope: float = 0.0
    stiffness: float = 0.0
    increment: list = dataclasses.field(default_factory=lambda: [0.0, 0.0])
    projection: DiscProjection = dataclasses.field(default_factory=DiscProjection)


def friction_term(f, at):
    """Friction at constraint f."""
    t, s = FrictionTerm(), at.scale
    t.normal = -f.sign * at.R[f.normal] * s / f.lumped
    # closed as the VI decides its active set: on the bound and pressed. A
    # pair on the bound that its force pulls off is released by the VI's
    # step; held by the bound of a cohesion or Tresca meanwhile, it would
    # stick while it opens, and the two decisions would cycle.
    t.closed = bool(on_foundation(f.gap - f.sign * at.X[f.normal] * s, s)) and t.normal > 0
    if t.closed:
        t.bound = slip_bound(f.law, t.normal) * f.lumped
        t.slope = slip_bound_slope(f.law, t.normal)
    # one c for the constraint, the mean of K's diagonal on its tangential
    # unknowns: with a c per unknown the slip c^-1 (theta - t_T) would not
    # point along t_T (friction would not be isotropic)
    t.stiffness = sum(at.stiffness[f.tangential[r]] for r in range(at.tangents)) / at.tangents
    trial = [0.0, 0.0]
    for r in range(at.tangents):
        i = f.tangential[r]
        t.increment[r] = at.X[i] * s - at.start[i]
        trial[r] = -at.R[i] * s + t.stiffness * t.increment[r]
    t.projection = project_on_disc(t.bound, trial, at.tangents)
    return t


def add_friction_forces(constraints, at, F):
    """F += P(theta) / s on the tangential rows of the constraints (F holds
    R on entry)."""
    for f in constraints:
        t = friction_term(f, at)
        for r in range(at.tangents):
            F[f.tangential[r]] += t.projection.force[r] / at.scale


def _add_row(K, row, weight, total):
    """Adds `weight` times row `row` of K to `total` (column -> value)."""
    cols, vals = K.getRow(row)
    for c, v in zip(cols, vals):
        total[int(c)] += weight * v


def _jacobian_row(f, t, r, at, K, first):
    """The generalised Jacobian's row r of constraint f, as column -> value;
    `first` is the global index of this rank's first row."""
    row, p = defaultdict(float), t.projection
    for q in range(at.tangents):
        i = f.tangential[q]
        d = p.d_trial[2 * r + q]
        _add_row(K, first + i, (1.0 if r == q else 0.0) - d, row)
        row[first + i] += d * t.stiffness
    w = -t.slope * f.sign * p.d_bound[r]
    if w != 0:
        _add_row(K, first + f.normal, w, row)
    return row


def friction_jacobian(constraints, at, K, J):
    """J = K but on the tangential rows of the constraints, there the
    generalised Jacobian of F_T: with D = dP/dtheta and g = dP/dbound,
        J_T = (I - D) K_T + c D - slope sign g K_N,
    combinations of the constraint's own rows of K (collective)."""
    K.copy(J, structure=PETSc.Mat.Structure.SUBSET_NONZERO_PATTERN)
    first = K.getOwnershipRange()[0]
    for f in constraints:
        t = friction_term(f, at)
        for r in range(at.tangents):
            row = _jacobian_row(f, t, r, at, K, first)
            cols = sorted(row)
            J.setValues([first + f.tangential[r]], cols, [row[c] for c in cols],
                        addv=PETSc.InsertMode.INSERT_VALUES)
    J.assemble()
