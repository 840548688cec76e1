"""The contact law of a pair (theory.md, "The contact law";
cpp/contact/contact_law.h): what the traction across a closed pair may be,
and the state it leaves the pair in (open, stick or slip: PairStatus). The
pairs (foundation_pair.py, fault_pair.py) say which nodes face which; the
VI solver knows no physics. The bound of the tangential traction t_T
(slip_bound), the exact disc in 3D: tresca when given, else cohesion +
friction max(t_N, 0) (Coulomb); frictionless (the default law) bound 0: a
closed pair slides freely. The bond: a pair's cohesion breaks for the rest
of the run where its effective normal traction falls to zero (a tension
cut-off at zero: the pair opens, or its solve can keep it closed only
pulled); friction stays."""
import dataclasses
import enum
import math
from typing import Optional


class PairStatus(enum.IntEnum):
    """The state of one constraint of a pair, with the values fault.xdmf's
    `state` writes. With g the pair's gap (the distance to the foundation;
    the opening [u].n + g0 of a fault pair), t_N >= 0 its normal traction
    (pressing) and t_T its tangential traction (a vector in the face, along
    the slip increment when the pair slips), a pair is
        open:   g > 0, no traction (t_N = 0, t_T = 0);
        stick:  g = 0, |t_T| < bound, no slip increment;
        slip:   g = 0, |t_T| = bound, the slip increment along t_T."""
    open = 0
    stick = 1
    slip = 2


@dataclasses.dataclass
class ContactLaw:
    """The contact law of a contact boundary or fault: Coulomb friction (the
    coefficient mu and the cohesion c), or Tresca's bound tau, which, when
    given, replaces both. Default: frictionless."""
    friction: float = 0.0
    cohesion: float = 0.0
    tresca: Optional[float] = None


@dataclasses.dataclass
class PairTraction:
    """What decides a constraint's state: whether it is closed (as the VI
    solver decides: on the foundation, the faces touching), its normal
    traction t_N (>= 0 pressing), the magnitude of its tangential traction
    |t_T|, and the traction scale the tolerance is relative to."""
    closed: bool = False
    normal: float = 0.0
    tangential: float = 0.0
    scale: float = 0.0


# A closed constraint sticks when |t_T| is below its bound by more than
# this, relative to the traction scale: above the error of the tractions
# (round-off of a direct solve, the 1e-10 relative residual of an iterative
# one), so that a slipping pair, on its bound, is not taken for one that
# sticks.
STATUS_TOLERANCE = 1e-8


def on_foundation(distance, scale):
    """Whether a constraint is closed: its node lies on the foundation (the
    faces touch) to round-off, within 1e-9 of the displacement scale (the
    one test behind the active set the coupling compares, the
    contact_active field and friction's bound)."""
    return distance <= 1e-9 * scale


def contact_law(friction):
    """The law a scene gives a contact boundary or a fault (its FrictionSpec)."""
    return ContactLaw(friction.friction, friction.cohesion, friction.tresca)


def frictionless(law):
    """Whether the law holds nothing tangentially (bound 0 whatever t_N)."""
    return law.tresca == 0 if law.tresca is not None else law.friction == 0 and law.cohesion == 0


def slip_bound(law, normal_traction):
    """The bound of |t_T|: tresca if given, else cohesion + friction
    max(t_N, 0) (a pulling t_N adds no friction)."""
    if law.tresca is not None:
        return law.tresca
    return law.cohesion + law.friction * max(normal_traction, 0.0)


def slip_bound_slope(law, normal_traction):
    """d bound / d t_N: the friction coefficient where Coulomb's bound grows
    with t_N (t_N > 0), else 0 (Tresca, a pulling t_N)."""
    return law.friction if law.tresca is None and normal_traction > 0 else 0.0


@dataclasses.dataclass
class DiscProjection:
    """The friction force of a constraint: its trial force theta = t_T + c s
    projected on the disc |t| <= bound (the return map; theory.md,
    "Friction"), with the derivatives the semismooth Newton step needs.
    Within the disc (bound > 0) the constraint sticks: force theta, d_trial
    the identity; outside it slips: force bound theta/|theta|, d_trial
    bound/|theta| (I - n n^T), d_bound n (n = theta/|theta|; 0 for theta = 0)."""
    force: list = dataclasses.field(default_factory=lambda: [0.0, 0.0])
    d_trial: list = dataclasses.field(default_factory=lambda: [0.0, 0.0, 0.0, 0.0])  # row-major
    d_bound: list = dataclasses.field(default_factory=lambda: [0.0, 0.0])
    stick: bool = False


def project_on_disc(bound, trial, tangents):
    """The projection of `trial` (its first `tangents` components: 1 in 2D,
    2 in 3D) on the disc of radius `bound` >= 0."""
    p = DiscProjection()
    size = math.hypot(trial[0], trial[1] if tangents == 2 else 0.0)
    # Strictly inside a disc of radius > 0: the bound 0 of an open or
    # frictionless constraint leaves it free, whatever theta.
    p.stick = bound > 0 and size <= bound
    if p.stick:
        p.force, p.d_trial = [trial[0], trial[1]], [1.0, 0.0, 0.0, 1.0]
        return p
    if size == 0:
        return p
    n = [trial[0] / size, trial[1] / size if tangents == 2 else 0.0]
    g = bound / size
    for r in range(tangents):
        p.force[r] = bound * n[r]
        p.d_bound[r] = n[r]
        for q in range(tangents):
            p.d_trial[2 * r + q] = g * ((1.0 if r == q else 0.0) - n[r] * n[q])
    return p


def pair_status(law, traction):
    """The state of one constraint: open if it is not closed; closed, stick
    when |t_T| < bound - STATUS_TOLERANCE * scale, else slip. A closed
    frictionless constraint therefore slips (bound 0: nothing holds it, and
    |t_T| is only the solve's error)."""
    if not traction.closed:
        return PairStatus.open
    bound = slip_bound(law, traction.normal)
    return PairStatus.stick if traction.tangential < bound - STATUS_TOLERANCE * traction.scale else PairStatus.slip
