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


@dataclasses.dataclass
class _RowWeights:
    """The weights of the generalised Jacobian's row r of constraint f: of
    K's rows T_q (1 - D_rq), of its row N, and D_rq c on the diagonal."""
    tangential: list
    diagonal: list
    normal: float


def _row_weights(f, t, r, tangents):
    d = [t.projection.d_trial[2 * r + q] for q in range(tangents)]
    return _RowWeights([(1.0 if r == q else 0.0) - d[q] for q in range(tangents)],
                       [d[q] * t.stiffness for q in range(tangents)],
                       -t.slope * f.sign * t.projection.d_bound[r])


def _add_row(K, row, weight, total):
    """Adds `weight` times row `row` of K to `total` (column -> value)."""
    cols, vals = K.getRow(row)
    for c, v in zip(cols, vals):
        total[int(c)] += weight * v


def _jacobian_row(f, t, r, at, K, first):
    """The generalised Jacobian's row r of constraint f, as column -> value;
    `first` is the global index of this rank's first row."""
    row, w = defaultdict(float), _row_weights(f, t, r, at.tangents)
    for q in range(at.tangents):
        _add_row(K, first + f.tangential[q], w.tangential[q], row)
        row[first + f.tangential[q]] += w.diagonal[q]
    if w.normal != 0:
        _add_row(K, first + f.normal, w.normal, row)
    return row


def _dense_jacobian(constraints, at, K, J):
    """friction_jacobian on a dense K (the condensed path's H): the rows
    combined as arrays, in place in J's."""
    k, j = K.getDenseArray(readonly=True), J.getDenseArray()
    for f in constraints:
        t = friction_term(f, at)
        for r in range(at.tangents):
            w = _row_weights(f, t, r, at.tangents)
            i = f.tangential[r]
            j[i, :] = w.normal * k[f.normal, :] + sum(w.tangential[q] * k[f.tangential[q], :]
                                                      for q in range(at.tangents))
            for q in range(at.tangents):
                j[i, f.tangential[q]] += w.diagonal[q]
    J.assemble()


def friction_jacobian(constraints, at, K, J):
    """J = K but on the tangential rows of the constraints, there the
    generalised Jacobian of F_T: with D = dP/dtheta and g = dP/dbound,
        J_T = (I - D) K_T + c D - slope sign g K_N,
    combinations of the constraint's own rows of K (collective)."""
    K.copy(J, structure=PETSc.Mat.Structure.SUBSET_NONZERO_PATTERN)
    if K.getType() == PETSc.Mat.Type.SEQDENSE:
        _dense_jacobian(constraints, at, K, J)
        return
    first = K.getOwnershipRange()[0]
    for f in constraints:
        t = friction_term(f, at)
        for r in range(at.tangents):
            row = _jacobian_row(f, t, r, at, K, first)
            cols = sorted(row)
            J.setValues([first + f.tangential[r]], cols, [row[c] for c in cols],
                        addv=PETSc.InsertMode.INSERT_VALUES)
    J.assemble()


def jacobian_weights(constraints, at):
    """The weights of the generalised Jacobian's rows (friction_jacobian), 5
    per tangential row in the constraints' order: of K's rows T_q, of the
    diagonal and of row N. J is K but for them, so while K stays, equal
    weights make an equal J (in 2D they change only with a constraint's
    state; in 3D also with a slip's direction)."""
    weights = []
    for f in constraints:
        t = friction_term(f, at)
        for r in range(at.tangents):
            w = _row_weights(f, t, r, at.tangents)
            pad = [0.0] * (2 - at.tangents)
            weights += w.tangential + pad + w.diagonal + pad + [w.normal]
    return weights


def all_gather_constraints(mine, comm):
    """Every rank's constraints on every rank, in rank order (collective)."""
    return [f for rank in comm.allgather(mine) for f in rank]
