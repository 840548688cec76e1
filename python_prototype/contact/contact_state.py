"""The contact state after a solve and its report (cpp/contact/contact_state.h):
the constraints' contact pressures and distances, each fault pair's jumps,
tractions and state under its contact law (contact_law.py), and what the
summary says of each contact boundary and fault."""
import dataclasses
import math

import numpy as np
from mpi4py import MPI

from .contact_law import ContactLaw, PairStatus, PairTraction, on_foundation, pair_status
from .contact_set import constraint_law


@dataclasses.dataclass
class PairState:
    """A fault pair after a solve: its + node (input index), fault (index
    among the contact's boundaries), opening [u].n + g0, contact traction
    (normal, >= 0 pressing), slip (the tangential jump, a vector of three
    components), tangential traction (three components: the one the + face
    exerts on the - face, along the slip increment when the pair slips) and
    its state under the fault's contact law (contact_law.py)."""
    node: int
    fault: int
    opening: float
    traction: float
    slip: np.ndarray
    tangential_traction: np.ndarray
    status: PairStatus = PairStatus.open
    # The slip since the start of the step (ContactSolver.set_slip_reference).
    slip_increment: np.ndarray = dataclasses.field(default_factory=lambda: np.zeros(3))
    # The cohesion its law holds: the fault's, 0 once its bond broke (contact_law.py).
    cohesion: float = 0.0


@dataclasses.dataclass
class FaultSummary:
    """What the summary says of a fault: its largest opening and slip, the
    measures (lumped lengths in 2D, areas in 3D) of its pairs that are
    closed, and of those in the states slip and stick, and the step's
    seismic moment."""
    name: str
    max_opening: float = 0.0
    max_slip: float = 0.0
    closed: float = 0.0
    slipping: float = 0.0
    # The seismic moment of the slip since the step's start: the sum over the
    # pairs of G |slip increment| times their lumped measure (N m; N m per
    # metre of thickness in 2D).
    moment: float = 0.0
    stuck: float = 0.0


class ContactState:
    """Contact diagnostics after a solve: the contact force at a node is the
    residual of the unconstrained equations there; divided by the lumped
    measure it is the contact pressure -sigma_nu >= 0."""

    def __init__(self):
        self.active_nodes = self.contact_nodes = 0
        self.max_penetration = self.max_pressure = self.min_pressure = 0.0
        self.max_complementarity = self.gap_scale = self.total_force = 0.0
        self.boundaries = []  # (name, force along -nu_F, active constraints) per contact boundary
        self.pairs = []       # this rank's fault pairs (PairState), each at its + node
        # Per fault (FaultSummary, in the order of the contact's boundaries):
        # its largest opening and slip, and its measures in contact, slipping
        # and stuck (a length in 2D, an area in 3D), on all ranks.
        self.faults = []


@dataclasses.dataclass
class ContactMeasurement:
    """What the contact solver measured at a solution x, per constraint of
    this rank (the set's order): its distance g - u.nu_F and contact
    pressure; and the arrays of x' = T x, of x' at the step's start and of
    the contact forces R' = T^{-T}(A x - b), where `displacement_dofs`
    places V's owned DOFs (change_of_variables.py: a pair's + node's
    tangential rows hold its tangential jump and force)."""
    set: object
    displacement_dofs: np.ndarray
    distance: np.ndarray
    pressure: np.ndarray
    gap_scale: float
    x: np.ndarray
    start: np.ndarray
    force: np.ndarray
    # per constraint at a junction, its jump [u] = u+ - u- at the solution
    # and at the step's start (junction_jumps); None without junctions
    jump: np.ndarray = None
    jump_start: np.ndarray = None


def junction_jumps(c, displacement_dofs, x, comm):
    """Per constraint of the ContactSet c at a junction of faults, the jump
    u+ - u- of its pair in u, a vector whose owned DOFs of V sit at
    `displacement_dofs` (a junction's pieces may be owned by several ranks;
    collective); zeros elsewhere, None when no rank has a junction."""
    if len(c.all_junction_nodes) == 0:  # on every rank alike
        return None
    u = x.getArray(readonly=True)
    # Each junction node's u from the rank that owns it, summed over the ranks.
    d = c.dim
    values = np.zeros((len(c.all_junction_nodes), d))
    first = d * c.all_junction_nodes - c.dof_offset
    mine = np.flatnonzero((first >= 0) & (first < len(displacement_dofs)))
    for i in range(d):
        values[mine, i] = u[displacement_dofs[first[mine] + i]]
    comm.Allreduce(MPI.IN_PLACE, values, op=MPI.SUM)
    position = {int(v): k for k, v in enumerate(c.all_junction_nodes)}
    jumps = np.zeros((len(c.dofs), 3))
    for k in np.flatnonzero(c.junction_nodes[:, 0] >= 0):
        plus, minus = c.junction_nodes[k]
        jumps[k, :d] = values[position[int(plus)]] - values[position[int(minus)]]
    return jumps


@dataclasses.dataclass
class ContactFields:
    """The output fields of the contact: each contact node's pressure, and 1
    where it is on its foundation."""
    pressure: object
    active: object


def contact_pressures(c, dofs, force):
    """Per constraint of the ContactSet `c` its contact pressure (> 0
    pressing), -sign R'[dof] / lumped measure, from the contact force R' =
    T^-T (A x - b) (its multiplier, ContactSolver._contact_force) at the
    constraints' DOFs `dofs` (this rank's)."""
    return -c.sign * force[dofs] / c.lumped


def contact_state(m, out, comm):
    """The contact state of a measurement; fills the output fields
    (collective)."""
    s = ContactState()
    s.gap_scale = m.gap_scale
    _fill_fields(m, out)
    _summarise(s, m, comm)
    _fault_states(s, m, comm)
    return s


def pair_tractions(state):
    """Each fault pair's contact traction (>= 0 pressing) by its fault's name
    and + node (where faults meet, a node is the + node of several): what a
    fault's cells average into their effective normal stress
    (FaultAperture.cell_means)."""
    return {(state.boundaries[pair.fault][0], pair.node): pair.traction for pair in state.pairs}


class ActiveSet:
    """The contact active set of a displacement: the flag of each contact
    DOF this rank owns and the number of active nodes on all ranks. Two sets
    of one run compare flag by flag (same_active_set): equal counts can hide
    nodes that open while as many close elsewhere."""

    def __init__(self, flags=None, nodes=0):
        self.flags = np.zeros(0, dtype=bool) if flags is None else flags
        self.nodes = nodes


def same_active_set(a, b, comm):
    """Whether a and b, two active sets on one partition, hold the same nodes
    on every rank (collective)."""
    return not comm.allreduce(not np.array_equal(a.flags, b.flags), op=MPI.LOR)


def _pair_state(m, k):
    """The state of the fault pair of constraint k but its status, from x',
    x' at the start of the step and R'."""
    c, d = m.set, m.set.dim
    frame = c.pair_frame[k]
    p = PairState(int(c.pair_node[k]), int(c.boundary[k]), m.distance[k], m.pressure[k], np.zeros(3),
                  np.zeros(3))
    # The + node's tangential rows r = 1..d-1 of x' = T x hold the jump's
    # tangential components in the pair's frame, w_J = R [u], and those of
    # R' the contact force on them (change_of_variables.py); R^T takes both
    # back to the global frame. The force becomes a traction as the normal
    # one does (-sign R'/lumped, sign +1 for a pair): the traction the + face
    # exerts on the - face, along the slip increment when the pair slips
    # (contact_law.py).
    if c.junction_nodes[k, 0] >= 0:  # frictionless; the jump in u (junction_jumps)
        for r in range(1, d):
            p.slip[:d] += frame[r, :d] * (frame[r, :d] @ m.jump[k, :d])
            p.slip_increment[:d] += frame[r, :d] * (frame[r, :d] @ (m.jump[k, :d] - m.jump_start[k, :d]))
        return p
    for r in range(1, d):
        row = m.displacement_dofs[c.dofs[k] + r]
        p.slip[:d] += frame[r, :d] * m.x[row]
        p.slip_increment[:d] += frame[r, :d] * (m.x[row] - m.start[row])
        p.tangential_traction[:d] -= frame[r, :d] * m.force[row] / c.lumped[k]
    return p


def _traction_scale(pressure, pairs, comm):
    """The largest contact traction, normal or tangential, of the
    constraints on all ranks: the scale of the states' tolerance
    (collective)."""
    scale = np.abs(pressure).max(initial=0.0)
    for p in pairs:
        scale = max(scale, math.hypot(*p.tangential_traction))
    return comm.allreduce(scale, op=MPI.MAX)


def _summarise_faults(s, m, constraint, summary_of, comm):
    """Each fault's summary from its pairs' states (collective): the largest
    opening and slip; the measures closed, slipping and stuck, and the
    moment."""
    c = m.set
    scale = _traction_scale(m.pressure, s.pairs, comm)
    largest, measure = np.zeros(2 * len(s.faults)), np.zeros(4 * len(s.faults))
    for p, k in zip(s.pairs, constraint):
        closed = bool(on_foundation(m.distance[k], s.gap_scale))
        # a junction's pairs are frictionless whatever their faults' laws
        # (theory.md, "Faults where they meet"): closed, they slip
        law = ContactLaw() if c.junction_nodes[k, 0] >= 0 else constraint_law(c, k)
        p.status = pair_status(law, PairTraction(closed, p.traction, math.hypot(*p.tangential_traction), scale))
        p.cohesion = law.cohesion
        f = summary_of[p.fault]
        largest[2 * f] = max(largest[2 * f], p.opening)
        largest[2 * f + 1] = max(largest[2 * f + 1], math.hypot(*p.slip))
        measure[4 * f] += c.lumped[k] if closed else 0.0
        measure[4 * f + 1] += c.lumped[k] if p.status == PairStatus.slip else 0.0
        measure[4 * f + 2] += c.lumped[k] if p.status == PairStatus.stick else 0.0
        measure[4 * f + 3] += c.shear_modulus[k] * math.hypot(*p.slip_increment) * c.lumped[k]
    comm.Allreduce(MPI.IN_PLACE, largest, op=MPI.MAX)
    comm.Allreduce(MPI.IN_PLACE, measure, op=MPI.SUM)
    for f, summary in enumerate(s.faults):
        summary.max_opening, summary.max_slip = largest[2 * f], largest[2 * f + 1]
        summary.closed, summary.slipping, summary.stuck, summary.moment = measure[4 * f:4 * f + 4]


def _fault_states(s, m, comm):
    """The fault pairs' states and summaries (collective)."""
    c = m.set
    summary_of = np.cumsum(c.faults) - 1  # of a fault's boundary
    s.faults = [FaultSummary(name) for name, fault in zip(c.boundaries, c.faults) if fault]
    if not s.faults:
        return
    constraint = np.flatnonzero(c.pair_node >= 0)  # of each pair
    s.pairs = [_pair_state(m, k) for k in constraint]
    _summarise_faults(s, m, constraint, summary_of, comm)


def _fill_fields(m, out):
    """The output fields of the constraints' pressures and distances; a node
    on two foundations shows the larger pressure."""
    active = on_foundation(m.distance, m.gap_scale)
    out.pressure.x.array[:] = 0.0
    out.active.x.array[:] = 0.0
    nodes = m.set.output_dofs
    out.pressure.x.array[nodes] = m.pressure
    np.maximum.at(out.pressure.x.array, nodes, m.pressure)
    np.maximum.at(out.active.x.array, nodes, active * 1.0)
    out.pressure.x.scatter_forward()
    out.active.x.scatter_forward()


def _summarise(s, m, comm):
    """The diagnostics of the constraints' pressures and distances
    (collective)."""
    c, pressure, distance = m.set, m.pressure, m.distance
    active = on_foundation(distance, s.gap_scale)
    s.active_nodes = comm.allreduce(int(active.sum()), op=MPI.SUM)
    s.contact_nodes = comm.allreduce(len(c.dofs), op=MPI.SUM)
    s.max_penetration = comm.allreduce((-distance).max(initial=-np.inf), op=MPI.MAX)
    s.max_complementarity = comm.allreduce(np.abs(pressure * distance).max(initial=0.0), op=MPI.MAX)
    s.max_pressure = comm.allreduce(pressure.max(initial=-np.inf), op=MPI.MAX)
    s.min_pressure = comm.allreduce(pressure.min(initial=np.inf), op=MPI.MIN)
    force = 0.0  # sum of the nodal contact forces along -nu_F, summed in order as the C++
    for p_k, lumped in zip(pressure, c.lumped):
        force += p_k * lumped
    s.total_force = comm.allreduce(force, op=MPI.SUM)
    s.boundaries = []  # (name, sum of nodal contact forces along -nu_F, active constraints)
    for b, name in enumerate(c.boundaries):
        mine = c.boundary == b
        local = 0.0
        for p_k, lumped in zip(pressure[mine], c.lumped[mine]):
            local += p_k * lumped
        s.boundaries.append((name, comm.allreduce(local, op=MPI.SUM),
                             comm.allreduce(int(active[mine].sum()), op=MPI.SUM)))
