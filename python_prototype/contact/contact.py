"""Signorini contact against rigid foundations of any normal nu_F and
between a fault's faces (alg. "Mechanics with frictionless Signorini
contact"; friction: contact_law.py; cpp/contact/contact.h), for the
mechanics and the monolithic systems alike.

The energy is quadratic, so with A the system matrix and b its load vector
the variational inequality is the bound-constrained problem: find x' with
l <= x' <= g and F(x') = A' x' - b' complementary to the bounds, in the
variables x' = T x of change_of_variables.py, where each constraint
u.nu_F <= g_a is a bound on one DOF (T = I, A' = A when every normal is a
coordinate axis). PETSc's reduced-space active-set Newton (SNES
vinewtonrsls) solves it. With friction the stick/slip states are found by an
active-set iteration around it; in 3D a slipping pair's force follows its
slip increment, and F is not linear (_solve_with_friction, _slip_force).
"""
import dataclasses
import math

import numpy as np
from mpi4py import MPI
from petsc4py import PETSc

from ..assembly.linear_algebra import set_lag_preconditioner
from .change_of_variables import ChangeOfVariables
from .contact_law import STATUS_TOLERANCE, ContactLaw, PairStatus, PairTraction, pair_status, slip_bound
from .contact_set import ContactSet
from .fault_pair import add_fault_pairs
from .foundation_pair import add_foundation_pairs
from .schur_complement import SchurComplement
from ..solvers.inactive_set_preconditioner import InactiveSetPreconditioner
from ..solvers.options import OptionsError, system_name
from ..solvers.solver import (ITERATIVE_TOLERANCE, LinearSolver, Method, SolverError, SolverStage, Structure,
                     reason_name, set_default_option, set_relative_tolerance)
from ..scene.scene import agree_on_error


def locate_contact(scene, domain, F, V):
    """The ContactSet of the scene: its contact boundaries against their
    foundations (foundation_pair.py), then the faults' node pairs
    (fault_pair.py). Raises SceneError, the same on every rank, for the
    first bad input they find (collective)."""
    c = ContactSet(domain.dim, V.sub(0).collapse()[0], V.dofmap.index_map_bs * V.dofmap.index_map.local_range[0])
    error = []  # the first bad input on this rank
    add_foundation_pairs(scene, domain, F, V, c, error)
    add_fault_pairs(scene, domain, F, V, c, error)
    agree_on_error(error[0] if error else "", domain.mesh.comm)
    c.dofs, c.sign = np.array(c.dofs, dtype=np.int32), np.array(c.sign, dtype=np.int32)
    c.gap, c.lumped, c.normal = np.array(c.gap), np.array(c.lumped), np.array(c.normal)
    c.output_dofs = np.array(c.output_dofs, dtype=np.int32)
    c.boundary = np.array(c.boundary, dtype=np.int32)
    c.pair_node = np.array(c.pair_node, dtype=np.int64)
    c.frictional = np.array(c.frictional, dtype=bool)
    return c


class ActiveSet:
    """The contact active set of a displacement (cpp/contact/contact.h): the
    flag of each contact DOF this rank owns and the number of active nodes
    on all ranks. Two sets of one run compare flag by flag
    (same_active_set): equal counts can hide nodes that open while as many
    close elsewhere."""

    def __init__(self, flags=None, nodes=0):
        self.flags = np.zeros(0, dtype=bool) if flags is None else flags
        self.nodes = nodes


# What a friction that fails to converge most often means.
NO_EQUILIBRIUM = " (a body that friction cannot hold has no quasi-static equilibrium)"


def _on_foundation(distance, scale):
    """Whether constraints are active: their nodes lie on the foundation to
    round-off, within 1e-9 of the displacement scale (the one test behind
    the active set the coupling compares and the contact_active field)."""
    return distance <= 1e-9 * scale


def pair_tractions(state):
    """Each fault pair's contact traction (>= 0 pressing) by its + node: what
    a fault's cells average into their effective normal stress
    (FaultAperture.cell_means)."""
    return {pair.node: pair.traction for pair in state.pairs}


def same_active_set(a, b, comm):
    """Whether a and b, two active sets on one partition, hold the same nodes
    on every rank (collective)."""
    return not comm.allreduce(not np.array_equal(a.flags, b.flags), op=MPI.LOR)


@dataclasses.dataclass
class ContactOperators:
    """The matrices of the contact problem: A, and P (A, or the fixed-stress
    matrix of the coupled system) that the iterative full path builds its
    preconditioner from."""
    A: PETSc.Mat
    P: PETSc.Mat
    # Whether A changes between most solves (the monolithic system with
    # conduit faults, whose rows follow their apertures): then forming H
    # anew each time costs more than it saves, and the full path is the
    # default.
    changing: bool = False


@dataclasses.dataclass
class ContactUnknowns:
    """What the contact solver constrains: the ContactSet, where each owned
    DOF of V sits in the solved vector (`displacement_dofs`: i itself for the
    mechanics system, its place in the mixed space for the monolithic one),
    and the rows of its mass balances (the rock's pressure rows and the
    conduit faults' of the monolithic system, local; none for the
    mechanics): in m^3/s where the others are in N, their residual is
    judged by their own load."""
    set: object
    displacement_dofs: object
    balance_rows: object = ()


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
    # The slip since the start of the step (set_slip_reference).
    slip_increment: np.ndarray = dataclasses.field(default_factory=lambda: np.zeros(3))


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
    """Contact diagnostics after a solve (cpp/contact/contact.h)."""

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
class _Friction:
    """A frictional constraint in the VI's numbering (replicated on every
    rank when condensed, this rank's own on the full system): the positions
    of its normal and d - 1 tangential unknowns, what its law needs, and the
    state and slip force of the current iterate (cpp/contact/contact.h,
    ContactSolver::Friction)."""
    normal: int = -1
    tangential: list = dataclasses.field(default_factory=lambda: [-1, -1])
    sign: float = 1.0
    gap: float = 0.0
    lumped: float = 0.0
    law: ContactLaw = dataclasses.field(default_factory=ContactLaw)
    status: PairStatus = PairStatus.stick
    # A slipping constraint's force: its bound (N) along its slip increment
    # (3D: the increment of the current x; 2D, or an increment too small to
    # point anywhere: `direction`, a unit vector in the tangential unknowns).
    bound: float = 0.0
    direction: list = dataclasses.field(default_factory=lambda: [0.0, 0.0])


_help_printed = set()  # the prefixes whose -help lines are out, as PETSc keeps them for the C++


def _read_condensed(comm, prefix, fallback):
    """-<prefix>contact_condensed, `fallback` when not given; with -help, the
    lines PETSc prints for the option the C++ registers (cpp/contact/contact.cpp,
    read_condensed), which petsc4py 3.18 cannot register."""
    options = PETSc.Options()
    try:
        condensed = options.getBool(prefix + "contact_condensed", fallback)
    except PETSc.Error:
        raise OptionsError(f"-{prefix}contact_condensed: not a boolean (true or false)") from None
    if options.hasName("help") and prefix not in _help_printed:
        _help_printed.add(prefix)
        text = ("pose the contact VI on the Schur complement of the contact DOFs (default with a direct solver and "
                f"at most {ContactSolver.max_condensed_dofs} contact DOFs), else on the whole system")
        PETSc.Sys.Print(f"----------------------------------------\nContact solver (biotcontact):\n"
                        f"  -{prefix}contact_condensed: <{str(fallback).upper()} : {str(condensed).upper()}> {text} "
                        "(docs/user-guide.md)", comm=comm)
    return condensed


def _use_condensation(comm, prefix, method, contact_dofs, changing):
    """-<prefix>contact_condensed, by default when the system is solved
    directly, C is small enough and A is not `changing` (forming H takes m
    solves, m more at each change of A)."""
    return _read_condensed(comm, prefix, method == Method.direct and contact_dofs <= ContactSolver.max_condensed_dofs
                           and not changing)


class ContactSolver:
    """The VI as a bound-constrained problem: l <= x <= g with F(x) = A x - b
    complementary to the bounds, bounds only on the contact DOFs. The energy
    is quadratic: A is the exact (constant) Jacobian. SNESVI decides "on the
    bound" with an absolute tolerance (1e-8), so it solves for x/s with s the
    displacement scale (largest gap or |x|): F = A (x/s) - b/s.

    As in cpp/contact/contact.h it runs condensed (by default with a direct solver
    and at most max_condensed_dofs contact DOFs: SNES on the dense Schur
    complement H of A on the contact DOFs, options prefix <prefix>contact_,
    the large matrix factorised once with the contact DOFs clamped) or full
    (SNES on A, the inactive-set factorisation reused while the set stays
    the same; operator_changed re-arms it after a reassembly)."""

    max_condensed_dofs = 2000  # above: dense H costs more than sparse refactorisations
    stagnation_window = 50  # Krylov iterations without 1% progress that count as stagnation
    max_friction_iterations = 100  # rounds of the friction's active-set iteration before it gives up
    slip_regularisation = 1e-9     # of a 3D slip force's direction, relative to the displacement scale

    def __init__(self, comm, system, method, operators, unknowns):
        """`system` the SystemLayout of the system it solves, `operators` its
        ContactOperators, `unknowns` the ContactUnknowns: on the iterative
        full path the Newton steps are preconditioned from P split along the
        system's fields."""
        prefix, structure, A, P = system.prefix, system.structure, operators.A, operators.P
        self.comm, self.A, self.P, self.fields, self.prefix = comm, A, P, list(system.fields), prefix
        self.set, self.structure = unknowns.set, structure
        if structure == Structure.spd:  # carries over to the inactive-set submatrices
            A.setOption(PETSc.Mat.Option.SPD, True)
        self.displacement_dofs = np.asarray(unknowns.displacement_dofs, dtype=np.int32)
        self.balance_rows = np.asarray(unknowns.balance_rows, dtype=np.int32)
        self.dofs = self.displacement_dofs[self.set.dofs] if len(self.set.dofs) else np.zeros(0, dtype=np.int32)
        self.force = A.createVecRight()
        # The start of the step like x, and x' of it (the faults' slip increments).
        self.x_start, self.x_start_vi = A.createVecRight(), A.createVecRight()
        self.x_start.set(0.0)
        self._make_change_of_variables()
        self.schur, self.schur_current, self.vi_stage, self.preconditioner = None, False, None, None
        condensed = _use_condensation(comm, prefix, method, comm.allreduce(len(self._contact_dofs()), op=MPI.SUM),
                                       operators.changing)
        if condensed:
            self._condense()
        else:
            self._pose_on_full_system()
        self._make_friction()
        vi_prefix = prefix + "contact_" if condensed else prefix
        self.preconditioner_on_P = not condensed and method == Method.iterative
        # friction in 3D on a system with mass balances: one Newton step
        # more once they are met (_balances_solved)
        self.balances_met = False
        self._create_snes(vi_prefix)
        if self.preconditioner_on_P:
            self.snes.getKSP().setMonitor(self._stagnation)
            self.preconditioner = InactiveSetPreconditioner(self.snes, self.P_vi, self.fields, prefix)
            self.set_tolerance(ITERATIVE_TOLERANCE)
        try:
            self.snes.setFromOptions()
        except PETSc.Error as e:
            raise OptionsError(f"the PETSc options of {system_name(prefix)} contact solver do not make a solver "
                               f"(PETSc error {e.ierr})") from None
        # Only the VI methods take bounds; asked of both prefixes, so that a
        # type given for the path not taken is not ignored silently either.
        for p in (prefix, prefix + "contact_"):
            given = PETSc.Options().getString(p + "snes_type", "")
            if given and given not in ("vinewtonrsls", "vinewtonssls"):
                raise OptionsError(f"-{p}snes_type {given}: the contact solver needs a bound-constrained method "
                                   "(vinewtonrsls or vinewtonssls)")
        self.newton_iterations = self.linear_iterations = self.active_set_changes = 0
        self.friction_iterations = 0  # rounds of the friction's active-set iteration (each one VI solve)
        self.scale = 1.0  # SNES works in units of the displacement scale
        self.pending = self.used = None  # active flags of the contact DOFs
        self.set_repeated, self.relative_target = False, 0.0
        # the residual on the mass balances' rows is small below the larger of
        # these: their load's times the relative tolerance (_pose), and rtol
        # times the solve's first (_balances_solved)
        self.balance_tolerance, self.balance_relative_target = 0.0, 0.0
        self.nonlinear = False  # 3D friction with a slipping constraint: F is not linear
        self.residuals, self.lowered_from = [], 0  # of the current Krylov solve (stagnation)
        # Called after each Newton step with its number: a long solve's sign
        # of life (the run's progress line).
        self.on_newton_step = None

    def _condense(self):
        """The VI on the Schur complement H = C A^-1 C^T of the contact DOFs
        (schur_complement.py): every unknown of the small dense problem is
        bounded but the tangential ones of friction."""
        dofs = self._contact_dofs()
        self.schur = SchurComplement(self.comm, self.prefix, self.A_vi, self.structure, dofs)
        self.vi_stage = SolverStage(self.prefix + "contact")
        self.vi_comm, self.vi_mpi_comm, self.K = PETSc.COMM_SELF, MPI.COMM_SELF, self.schur.H
        # Each rank's constraints come first among its contact DOFs, its
        # tangential ones (friction) after them: the bounded DOFs of H are the
        # constraints'.
        bounded, gap, sign = np.zeros(len(dofs)), np.zeros(len(dofs)), np.zeros(len(dofs))
        n = len(self.dofs)
        bounded[:n], gap[:n], sign[:n] = 1.0, self.set.gap, self.set.sign
        kept = np.flatnonzero(self.schur.gather(bounded) > 0)
        self.bounded = kept.astype(np.int32)
        self.bounded_gap = self.schur.gather(gap)[kept]
        self.bounded_sign = self.schur.gather(sign)[kept]
        self.x = PETSc.Vec().createSeq(self.schur.size(), comm=PETSc.COMM_SELF)
        # H is small and dense: LAPACK's factorisation, Cholesky when A is SPD.
        vi_prefix = self.prefix + "contact_"
        set_default_option(vi_prefix + "ksp_type", "preonly")
        set_default_option(vi_prefix + "pc_type", "cholesky" if self.structure == Structure.spd else "lu")
        set_default_option(vi_prefix + "pc_factor_mat_solver_type", "petsc")
        self._make_bound_vectors()

    def _contact_dofs(self):
        """The contact DOFs of the VI: each constraint's, then the tangential
        ones of the frictional constraints."""
        c = self.set
        tangential = [self.displacement_dofs[c.dofs[k] + r] for k in range(len(self.dofs))
                      if c.frictional[k] for r in range(1, c.dim)]
        return np.concatenate([self.dofs, np.array(tangential, dtype=np.int32)])

    def _make_friction(self):
        """The frictional constraints (_Friction) in the VI's numbering, once
        the VI is posed: on the full system this rank's, at their local
        positions; condensed, every rank's at their places in H (each rank's
        contact DOFs from its offset, in _contact_dofs()'s order), gathered
        to every rank."""
        c, d = self.set, self.set.dim
        first = self.schur.offset if self.schur else 0
        records = []
        following = len(self.dofs)  # the place of the next tangential DOF among this rank's
        for k in range(len(self.dofs)):
            law = c.laws[c.boundary[k]]
            if not c.frictional[k]:
                continue
            normal = first + k if self.schur else self.dofs[k]
            t = [-1, -1]
            for r in range(1, d):
                t[r - 1] = int(first + following if self.schur else self.displacement_dofs[c.dofs[k] + r])
                following += 1
            records.append(_Friction(int(normal), t, float(c.sign[k]), float(c.gap[k]), float(c.lumped[k]), law))
        self.friction = [f for rank in self.comm.allgather(records) for f in rank] if self.schur else records
        self.x_reference = self.stiffness = self.work = None
        self.J = None  # 3D friction: K plus the slip forces' derivative
        if not self.comm.allreduce(bool(self.friction), op=MPI.LOR):
            return
        self.x_reference, self.stiffness, self.work = (self.x.duplicate() for _ in range(3))
        self.x_reference.set(0.0)
        if d == 3:
            self.J = self.K.duplicate(copy=True)

    def _pose_on_full_system(self):
        """The VI on the full system: only the contact DOFs are bounded."""
        self.vi_comm, self.vi_mpi_comm, self.K = self.comm, self.comm, self.A_vi
        self.bounded, self.bounded_gap, self.bounded_sign = self.dofs, self.set.gap, self.set.sign
        self.x = self.A.createVecRight()
        self._make_bound_vectors()

    def _make_bound_vectors(self):
        """The residual and the bounds, unbounded until solve() sets the
        contact ones."""
        self.residual, self.lower, self.upper, self.b_scaled = (self.x.duplicate() for _ in range(4))
        self.lower.set(PETSc.NINFINITY)
        self.upper.set(PETSc.INFINITY)

    def _create_snes(self, vi_prefix):
        """The semismooth Newton VI solver (SNES vinewtonrsls) and its
        defaults; the user's -<vi_prefix>snes_* options override them."""
        self.lag_by_default = not PETSc.Options().hasName(vi_prefix + "snes_lag_preconditioner")
        self.snes_rtol_given = PETSc.Options().hasName(vi_prefix + "snes_rtol")
        # With friction in 3D the Jacobian changes every step: no lag for a
        # factorisation of it; the iterative path's preconditioner is built
        # from P and the inactive set alone, and is reused there too.
        lag = "-2" if self._lag_preconditioner() else "1"
        # with friction in 3D a backtracking search, but not on the coupled
        # system: the search's merit ||F||, the forces' (N), is blind to its
        # mass balances' rows (m^3/s), whose step it shrank to nothing
        balances = self.comm.allreduce(len(self.balance_rows), op=MPI.SUM)
        self.refine_balances = self.J is not None and balances > 0
        backtrack = self.J is not None and balances == 0
        for option, value in (("snes_lag_preconditioner", lag), ("snes_rtol", "1e-10"),
                              ("snes_stol", "1e-12"), ("snes_max_it", "100"),
                              # F is linear, K exact: the full step is exact on the active
                              # set; with friction in 3D the slip forces' directions make full
                              # steps overshoot: a backtracking search
                              ("snes_linesearch_type", "bt" if backtrack else "basic"),
                              # no cap on the step's length (PETSc's 1e8): x is in units of
                              # the displacement scale, the coupled system's pressures run to
                              # 1e10 and more, and a capped step crawls
                              ("snes_linesearch_maxstep", "1e300")):
            set_default_option(vi_prefix + option, value)
        self.snes = PETSc.SNES().create(self.vi_comm)
        self.snes.setOptionsPrefix(vi_prefix)
        self.snes.setType("vinewtonrsls")
        self.snes.setFunction(self._residual, self.residual)
        J = self.J if self.J is not None else self.K
        self.snes.setJacobian(self._jacobian, J, J)
        self.snes.setVariableBounds(self.lower, self.upper)
        self.snes.setConvergenceTest(self._converged)
        # At least one Newton step per solve, so the result never lags the
        # load (not with friction in 3D: its F is not linear, the residual
        # decides, and a backtracking search fails on a zero step).
        self.snes.setForceIteration(not backtrack)
        self.snes.setMonitor(self._monitor)

    def method(self):
        return f"condensed on {self.schur.size()} contact DOFs" if self.schur else "full"

    def set_tolerance(self, relative):
        """Solves to `relative` (iterative full path): the Krylov tolerance of
        each Newton step and the Newton tolerance (cpp/contact/contact.h says why)."""
        if not self.preconditioner:
            return
        set_relative_tolerance(self.snes.getKSP(), self.prefix, relative)
        if not self.snes_rtol_given:
            self.snes.setTolerances(rtol=relative)

    def preconditioner_setups(self):
        """Set-ups of the iterative full path's preconditioner (None otherwise)."""
        return (self.preconditioner.setups, self.preconditioner.setup_time) if self.preconditioner else None

    def schur_columns(self):
        return self.schur.columns if self.schur else 0

    def schur_time(self):
        return self.schur.time if self.schur else 0.0

    def operator_changed(self):
        """A was reassembled: H is formed again, "rebuild once, then reuse" re-armed."""
        self.schur_current = self.change_current = False
        if self.lag_by_default and self._lag_preconditioner():
            set_lag_preconditioner(self.snes, -2)

    def _lag_preconditioner(self):
        """Whether the Newton steps reuse the preconditioner until the inactive
        set or the operator changes: always but for a factorisation of the
        Jacobian of friction in 3D, which changes every step."""
        return self.J is None or self.preconditioner_on_P

    def _active_contact_dofs(self, x):
        """PETSc's rule (SNESVIGetActiveSetIS): on a bound to 1e-8, pushed
        against it; and whether a DOF lies on a bound that F does not push
        (clipped): the projection put it there after a step that left it
        free, so that step did not solve its equation."""
        X, F = x.getArray(readonly=True), self.snes.getFunction()[0].getArray(readonly=True)
        lo, up = self.lower.getArray(readonly=True), self.upper.getArray(readonly=True)
        i = self.bounded
        on_lower, on_upper = X[i] <= lo[i] + 1e-8, X[i] >= up[i] - 1e-8
        active = (on_lower & (F[i] > 0)) | (on_upper & (F[i] < 0))
        return active, bool(np.any((on_lower | on_upper) & ~active))

    def _monitor(self, snes, iteration, norm):
        """Before each Newton step (and after the last): the set the next step uses."""
        if iteration > 0:
            changed = self.used is not None and not np.array_equal(self.pending, self.used)
            self.active_set_changes += int(self.vi_mpi_comm.allreduce(int(changed), op=MPI.MAX))
            self.used = self.pending
        self.pending, clipped = self._active_contact_dofs(snes.getSolution())
        if iteration > 0:
            differs = not np.array_equal(self.pending, self.used) or clipped
            self.set_repeated = not self.vi_mpi_comm.allreduce(int(differs), op=MPI.MAX)
            if self.on_newton_step is not None:
                self.on_newton_step(iteration)

    def _stagnation(self, ksp, iteration, rnorm):
        """A Newton step's Krylov solve that reduces its residual by less than
        1% over the last stagnation_window iterations (a singular reduced
        system, a round-off right-hand side) is stopped: its iteration limit
        is lowered to now (DIVERGED_ITS) and restored at the next solve;
        the contact solve restarts from the clamped state (cpp/contact/contact.cpp)."""
        if iteration == 0:
            self.residuals = []
            if self.lowered_from:
                ksp.setTolerances(max_it=self.lowered_from)
            self.lowered_from = 0
        self.residuals.append(rnorm)
        w = self.stagnation_window
        if iteration >= w and rnorm > 0.99 * self.residuals[iteration - w]:
            self.lowered_from = ksp.getTolerances()[3]
            ksp.setTolerances(max_it=iteration)

    def _converged(self, snes, iteration, norms):
        """PETSc's test of the VI methods after at least one step, and the
        stopping rule of the primal-dual active set method: the step kept its
        active set, so x solves the VI even where the residual's round-off
        lies above atol (cpp/contact/contact.cpp). With slip forces along the
        slip increment (3D) F is not linear: only the residual says when it
        is solved."""
        _, _, fnorm = norms
        rtol, atol, _, _ = snes.getTolerances()
        if iteration == 0:
            self.relative_target = rtol * fnorm
            self.balance_relative_target = rtol * self._balance_norm(snes.getFunction()[0])
            self.balances_met = False
        balances = self._balances_may_stop(self._balances_solved(snes, iteration))
        reasons = PETSc.SNES.ConvergedReason
        if not np.isfinite(fnorm):
            return reasons.DIVERGED_FNORM_NAN
        # a step taken, or the start with friction in 3D
        if (iteration > 0 or self.J is not None) and fnorm < atol and balances:
            return reasons.CONVERGED_FNORM_ABS
        if iteration > 0 and fnorm < self.relative_target and balances:
            return reasons.CONVERGED_FNORM_RELATIVE
        if iteration > 0 and self.set_repeated and not self.nonlinear:
            return reasons.CONVERGED_ITS
        return reasons.CONVERGED_ITERATING

    def _residual(self, snes, x, F):
        """F(x) = K x - b/s: the gradient of the quadratic energy, in units
        of s; with friction, plus the slip forces."""
        self.K.mult(x, F)
        F.axpy(-1.0, self.b_scaled)
        if self.friction:
            self._add_slip_forces(x, F)

    def _jacobian(self, snes, x, J, P):
        """The constant matrix K (A, or H formed once per A); with friction
        in 3D, K plus the derivative of the slip forces' directions."""
        if self.J is None:
            return
        self.K.copy(self.J, structure=PETSc.Mat.Structure.SAME_NONZERO_PATTERN)
        self._add_slip_jacobian(x, self.J)

    def displacement_scale(self, x):
        """The largest gap or |displacement| (collective)."""
        local = max(self.set.gap.max(initial=0.0),
                    np.abs(x.getArray(readonly=True)[self.displacement_dofs]).max(initial=0.0))
        s = self.comm.allreduce(local, op=MPI.MAX)
        return s if s > 0 else 1.0

    def solve(self, b, x):
        """Solves the VI; x holds the initial guess on entry. With friction,
        the stick/slip states of the frictional constraints are found by an
        active-set iteration around it (_solve_with_friction); their slip
        increments are measured from the slip reference."""
        self._change_operators()
        b_vi, x_vi = b, self._to_vi(x)
        if self.change:
            self.change.dual(b, self.b_vi)
            b_vi = self.b_vi
        if self.schur and not self.schur_current:
            self.schur.assemble()
            self.schur_current = True
        # SNESVI decides "on the bound" with an absolute tolerance (1e-8), so
        # it works on x / s with s the displacement scale (largest gap or
        # |x|); the residual K (x/s) - b/s has the same Jacobian K.
        self.scale = self.displacement_scale(x_vi)
        self._set_bounds()
        self._pose(b_vi, x_vi, self.scale)
        if self.x_reference is not None:
            self._solve_with_friction()
        else:
            self._solve_vi()
        self.x.scale(self.scale)
        if self.schur:
            self.schur.extend(b_vi, self.x.getArray(readonly=True), x_vi)
        else:
            self.x.copy(x_vi)
        if self.change:
            self.change.backward(x_vi, x)

    def set_slip_reference(self, x):
        """A time step (or window) starts at x: the slip increments
        (friction's, and those fault.xdmf writes) are measured from it
        (collective)."""
        x.copy(self.x_start)
        if self.x_reference is None:
            return
        x_vi = self._to_vi(x)
        if self.schur:
            with self.x_reference as reference:
                reference[:] = self.schur.restrict_to_contact(x_vi)
        else:
            x_vi.copy(self.x_reference)

    def _solve_with_friction(self):
        """Friction by the primal-dual active-set method (Hueber, Stadler and
        Wohlmuth 2008) around the VI: each round solves the VI with every
        stuck tangential unknown held at its reference (no slip increment)
        and every slipping one loaded by its slip force, then takes from that
        solution the trial force theta = t_T + c ds (t_T the tangential
        contact force, ds the slip increment, c the diagonal stiffness) of
        each closed constraint: stuck when |theta| is within the bound, else
        slipping with the bound's force, along theta in 2D, and in 3D along
        its slip increment within the VI (the exact disc, _slip_force).
        When no state and no slip force changes, the round's solution
        satisfies the law: a stuck constraint's force is within the bound, a
        slipping one's is on it and along its slip increment. The states and
        forces carry over to the next solve, whose rounds usually start from
        the right ones."""
        self.K.getDiagonal(self.stiffness)
        for _ in range(self.max_friction_iterations):
            self._apply_friction()
            if not self._solve_round():
                continue
            self.friction_iterations += 1
            if self._update_friction():
                return
        raise SolverError(f"friction: the stick and slip states did not settle in "
                          f"{self.max_friction_iterations} rounds of the active-set iteration" + NO_EQUILIBRIUM)

    def _solve_round(self):
        """One round's VI; when it fails with slipping pairs in 3D, the
        weakest of them stick: False (the round is to be repeated)."""
        try:
            self._solve_vi()
            return True
        except SolverError:
            if not self.nonlinear:
                raise
        if not self._stick_weakest():
            raise SolverError("friction: the contact solver did not converge with the slipping pairs of this round"
                              + NO_EQUILIBRIUM)
        return False

    def _apply_friction(self):
        """Bounds of the tangential unknowns from the states: a stuck one held
        at its reference, the others free; F is not linear (3D) when one
        slips (collective)."""
        scale = self.scale
        reference = self.x_reference.getArray(readonly=True)
        with self.lower as lo, self.upper as up:
            for f in self.friction:
                for r in range(self.set.dim - 1):
                    t = f.tangential[r]
                    stuck = f.status == PairStatus.stick
                    lo[t] = reference[t] / scale if stuck else PETSc.NINFINITY
                    up[t] = reference[t] / scale if stuck else PETSc.INFINITY
        slipping = self.set.dim == 3 and any(f.status == PairStatus.slip for f in self.friction)
        if not self.schur:
            slipping = self.comm.allreduce(slipping, op=MPI.LOR)
        self.nonlinear = slipping

    def _slip_force(self, f, X, reference, increment):
        """The slip force of constraint f at the VI's unknown X (N, along its
        tangential unknowns); its slip increment there goes into the list
        `increment` (as the C++ reference parameter)."""
        tangents = self.set.dim - 1
        for r in range(tangents):
            increment[r] = X[f.tangential[r]] * self.scale - reference[f.tangential[r]]
        if f.status != PairStatus.slip:
            return [0.0, 0.0]
        # The friction opposes the slip: K x - b = -force on a slipping unknown.
        if tangents == 1:
            return [f.bound * f.direction[0], f.bound * f.direction[1]]
        # 3D: along s, regularised, bound s / sqrt(|s|^2 + e^2) with e =
        # slip_regularisation times the scale: the gradient of the convex
        # bound sqrt(|s|^2 + e^2), which keeps Newton's equations solvable
        # where a constraint marked slipping should stick (its |s| then falls
        # to about e, and the next round sticks it); off by (e/|s|)^2 / 2
        # where it slips.
        e = self.slip_regularisation * self.scale
        size = np.sqrt(increment[0] * increment[0] + increment[1] * increment[1] + e * e)
        return [f.bound * increment[0] / size, f.bound * increment[1] / size]

    def _add_slip_forces(self, x, F):
        """F += the slip forces (in units of the scale) at x."""
        X, reference = x.getArray(readonly=True), self.x_reference.getArray(readonly=True)
        increment = [0.0, 0.0]
        with F as R:
            for f in self.friction:
                force = self._slip_force(f, X, reference, increment)
                for r in range(self.set.dim - 1):
                    R[f.tangential[r]] += force[r] / self.scale

    def _add_slip_jacobian(self, x, J):
        """J += the slip forces' derivative at x (3D: the direction follows
        the slip increment)."""
        # d(bound s/r)/ds = bound/r (I - s s^T/r^2), r = sqrt(|s|^2 + e^2)
        # (_slip_force): in the units of K (the residual is in units of the
        # scale, so is x).
        start = J.getOwnershipRange()[0]
        X, reference = x.getArray(readonly=True), self.x_reference.getArray(readonly=True)
        s = [0.0, 0.0]
        for f in self.friction:
            self._slip_force(f, X, reference, s)
            if f.status != PairStatus.slip:
                continue
            e = self.slip_regularisation * self.scale
            size = np.sqrt(s[0] * s[0] + s[1] * s[1] + e * e)
            rows = np.array([start + f.tangential[0], start + f.tangential[1]], dtype=PETSc.IntType)
            n, g = [s[0] / size, s[1] / size], f.bound / size
            block = [g * (1 - n[0] * n[0]), -g * n[0] * n[1], -g * n[1] * n[0], g * (1 - n[1] * n[1])]
            J.setValues(rows, rows, block, addv=PETSc.InsertMode.ADD_VALUES)
        J.assemble()

    def _stick_weakest(self):
        """After a failed VI with slipping constraints (3D: a constraint that
        should stick has no slip direction to settle on): the ones whose slip
        increment is smallest stick; False when none slips (collective)."""
        X, reference = self.x.getArray(readonly=True), self.x_reference.getArray(readonly=True)
        size, largest, s = [-1.0] * len(self.friction), 0.0, [0.0, 0.0]
        for k, f in enumerate(self.friction):
            if f.status == PairStatus.slip:
                self._slip_force(f, X, reference, s)
                size[k] = np.hypot(s[0], s[1])
                largest = max(largest, size[k])
        if not self.schur:
            largest = self.comm.allreduce(largest, op=MPI.MAX)
        any_stuck = False
        for k, f in enumerate(self.friction):
            if size[k] >= 0 and size[k] <= 1e-2 * largest:
                f.status, any_stuck = PairStatus.stick, True
        if not self.schur:
            any_stuck = self.comm.allreduce(any_stuck, op=MPI.LOR)
        return any_stuck

    def _update_friction(self):
        """The states and slip forces of the VI's solution; True when
        neither changed (collective). The contact forces R = K x - b (without
        the slip forces; in units of the scale) give each constraint its
        normal traction, so its bound, and, stuck, the force that holds it."""
        self.K.mult(self.x, self.work)
        self.work.axpy(-1.0, self.b_scaled)
        X, R = self.x.getArray(readonly=True), self.work.getArray(readonly=True)
        reference, c = self.x_reference.getArray(readonly=True), self.stiffness.getArray(readonly=True)
        scale, tangents = self.scale, self.set.dim - 1
        bound, trial, increment, largest = [], [], [], 0.0
        for f in self.friction:
            closed = _on_foundation(f.gap - f.sign * X[f.normal] * scale, scale)
            normal = -f.sign * R[f.normal] * scale / f.lumped
            bound.append(slip_bound(f.law, normal) * f.lumped if closed else -1.0)
            trial.append([0.0, 0.0])
            increment.append([0.0, 0.0])
            self._slip_force(f, X, reference, increment[-1])
            for r in range(tangents):
                trial[-1][r] = -R[f.tangential[r]] * scale + c[f.tangential[r]] * increment[-1][r]
            largest = max(largest, bound[-1])
        if not self.schur:  # on the full system each rank holds its own constraints
            largest = self.comm.allreduce(largest, op=MPI.MAX)
        change, changed = 0.0, False
        for f, limit, theta, ds in zip(self.friction, bound, trial, increment):
            before = [f.bound * f.direction[0], f.bound * f.direction[1]]
            status = self._next_status(f, limit, theta, ds, largest)
            if status == PairStatus.slip:
                # 2D: the direction stays (a reversal sticks first); 3D: along
                # the increment, or the trial force for a constraint that
                # starts to slip.
                along = ds if f.status == PairStatus.slip and tangents == 2 else theta
                size = np.hypot(along[0], along[1])  # C's hypot, as std::hypot
                if not (f.status == PairStatus.slip and tangents == 1) and size > 0:
                    f.direction = [along[0] / size, along[1] / size]
            f.bound = limit if status == PairStatus.slip else 0.0
            for r in range(tangents):
                change = max(change, abs(f.bound * f.direction[r] - before[r]))
            changed = changed or status != f.status
            f.status = status
        if not self.schur:
            changed = self.comm.allreduce(changed, op=MPI.LOR)
            change = self.comm.allreduce(change, op=MPI.MAX)
        return not changed and change <= 1e-10 * largest

    def _next_status(self, f, bound, trial, increment, largest):
        """The next state of constraint f from its bound (-1: open), trial
        force and slip increment; `largest` is the largest bound (the
        tolerance's scale)."""
        if bound < 0:
            return PairStatus.open
        # A slipping constraint that moved against its slip force would have
        # friction drive it: it sticks instead (without this rule the force of
        # a constraint that should stick flips sign every round when c exceeds
        # twice the stiffness its neighbours leave it).
        work = f.direction[0] * increment[0] + f.direction[1] * increment[1]
        if f.status == PairStatus.slip and work <= 0:
            return PairStatus.stick
        # The trial force theta = t_T + c s: within the bound, the constraint sticks.
        return PairStatus.stick if np.hypot(trial[0], trial[1]) <= bound + STATUS_TOLERANCE * largest \
            else PairStatus.slip

    def _solve_vi(self):
        """The VI with the current bounds and load; retried from the clamped
        state when the first attempt fails; raises SolverError when both do."""
        reason = self._snes_solve()
        self._count(reason)
        if reason < 0:
            # A body held in the normal direction by the foundation alone is
            # semi-coercive: from a start where no contact DOF pushes on its
            # bound the reduced system is singular. Start again with every
            # contact node on the foundation; the contact forces there say
            # which nodes to release.
            self.clamped_start()
            reason = self._snes_solve()
            self._count(reason)
        if reason < 0:
            raise SolverError("the contact solver (SNES vinewtonrsls) did not converge: "
                              + reason_name(PETSc.SNES.ConvergedReason, reason))

    def _set_bounds(self):
        """u.nu_F = sign x'[dof] <= g_a: x'[dof] <= g_a or x'[dof] >= -g_a,
        in units of the displacement scale."""
        upper, lower = self.bounded_sign > 0, self.bounded_sign < 0
        with self.upper as up:
            up[self.bounded[upper]] = self.bounded_gap[upper] / self.scale
        with self.lower as lo:
            lo[self.bounded[lower]] = -self.bounded_gap[lower] / self.scale

    def _pose(self, b, x, scale):
        """The scaled load and start of the VI (on C alone when condensed:
        (H, g) with y = x_C), its absolute tolerance relative to the load
        unless -snes_atol is given: scale-free."""
        if self.schur:
            with self.b_scaled as g:
                g[:] = self.schur.condensed_load(b)
            with self.x as y:
                y[:] = self.schur.restrict_to_contact(x)
        else:
            b.copy(self.b_scaled)
            x.copy(self.x)
        self.b_scaled.scale(1.0 / scale)
        self.x.scale(1.0 / scale)
        if not PETSc.Options().hasName(self.snes.getOptionsPrefix() + "snes_atol"):
            # With friction in 3D the residual decides the last step (F is not
            # linear): tighter, Newton's last steps are quadratic.
            relative = 1e-12 if self.J is not None else 1e-10
            self.snes.setTolerances(atol=max(relative * self.b_scaled.norm(), 1e-300))
        # the mass balances' rows, by their own load
        self.balance_tolerance = (1e-12 if self.J is not None else 1e-10) * self._balance_norm(self.b_scaled)

    def _balance_norm(self, v):
        """The norm of v on the mass balances' rows (none when condensed;
        collective)."""
        if self.schur:  # the contact DOFs alone
            return 0.0
        rows = v.array_r[self.balance_rows]
        return float(np.sqrt(self.comm.allreduce(float(np.sum(rows ** 2)), op=MPI.SUM)))

    def _balances_solved(self, snes, iteration):
        """Whether the residual is small on the mass balances' rows: the norm
        F and the load take over the whole system is the forces' (N against
        m^3/s), blind to them (collective)."""
        norm = self._balance_norm(snes.getFunction()[0])
        return norm <= self.balance_tolerance or (iteration > 0 and norm <= self.balance_relative_target)

    def _balances_may_stop(self, met):
        """Whether a solve whose balances are solved (`met`) may stop: with
        friction in 3D on a system with mass balances, only one Newton step
        after they were first met in this solve. The residual alone decides
        the last step there, and a balance's tolerance lies far above its
        round-off where its load holds terms that cancel at the solution (a
        fault's ends held at p_D): the step more takes the balances to
        round-off (cpp/contact/contact.cpp)."""
        if not met or not self.refine_balances:
            return met
        refined, self.balances_met = self.balances_met, True
        return refined

    def _count(self, reason):
        """Every attempt's steps count, a failed Krylov solve's iterations
        too (SNES leaves them out of its own count)."""
        failed = self.snes.getKSP().getIterationNumber() \
            if reason == PETSc.SNES.ConvergedReason.DIVERGED_LINEAR_SOLVE else 0
        self.newton_iterations += self.snes.getIterationNumber()
        self.linear_iterations += self.snes.getLinearSolveIterations() + failed

    def _snes_solve(self):
        try:
            if self.vi_stage:
                with self.vi_stage:
                    self.snes.solve(None, self.x)
            else:
                self.snes.solve(None, self.x)
        except PETSc.Error as e:
            raise SolverError(f"the contact solver (SNES vinewtonrsls) failed: PETSc error {e.ierr}") from None
        return self.snes.getConvergedReason()

    def clamped_start(self):
        """Every contact DOF on its bound; the other DOFs (none when
        condensed) solve A x = b/s with the contact rows and columns
        eliminated and the known values moved to the right-hand side."""
        up, lo = self.upper.getArray(readonly=True), self.lower.getArray(readonly=True)
        with self.x as x:
            x[self.bounded] = np.where(self.bounded_sign > 0, up[self.bounded], lo[self.bounded])
        if self.schur:
            return
        rows = (self.x.getOwnershipRange()[0] + self.bounded).astype(PETSc.IntType)
        def clamped_copy(M, rhs=None):
            C = M.duplicate(copy=True)
            modes = M.getNearNullSpace()  # for AMG: the duplicate does not keep it
            if modes is not None and modes.handle:
                C.setNearNullSpace(modes)
            C.zeroRowsColumns(rows, 1.0, self.x if rhs is not None else None, rhs)
            return C
        rhs = self.b_scaled.copy()
        A = clamped_copy(self.A_vi, rhs)
        P = A if self.P_vi is self.A_vi else clamped_copy(self.P_vi)
        LinearSolver(self.comm, self.prefix, A, P, self.structure, self.fields).solve(self.x, rhs)

    def _make_change_of_variables(self):
        """The change of variables of the inclined and curved foundations,
        made when any node needs one (collective), and its operators."""
        self.A_vi, self.P_vi, self.change, self.change_current = self.A, self.P, None, True
        self.x_vi = self.b_vi = None
        if self.comm.allreduce(len(self.set.blocks), op=MPI.SUM) == 0:
            return
        requested = np.concatenate([dofs for dofs, _ in self.set.blocks] or [np.zeros(0, dtype=np.int64)])
        positions = iter(self._solved_positions(requested))
        blocks = [([next(positions) for _ in dofs], T) for dofs, T in self.set.blocks]
        self.change = ChangeOfVariables(self.A, blocks, self.structure == Structure.spd)
        self.A_vi = self.change.congruence(self.A)
        self.P_vi = self.A_vi if self.P is self.A else self.change.congruence(self.P)
        self.x_vi, self.b_vi = self.A.createVecRight(), self.A.createVecRight()
        # The rigid-body modes of a field (the displacement of the coupled
        # system) change with its DOFs.
        for k, f in enumerate(self.fields):
            if f.near_nullspace is not None:
                self.fields[k] = dataclasses.replace(
                    f, near_nullspace=self.change.transformed(f.near_nullspace, f.dofs, self.x_vi))

    def _solved_positions(self, dofs):
        """The global position in the solved vector of each global DOF of V
        in `dofs`, wherever it is owned (collective): a fault's other face
        may be owned by another rank, so every request goes to every rank."""
        start = self.A.getOwnershipRange()[0]
        owned = len(self.displacement_dofs)
        requests = self.comm.allgather(np.asarray(dofs, dtype=np.int64))
        everything = np.concatenate(requests)
        local = everything - self.set.dof_offset
        mine = (local >= 0) & (local < owned)
        answer = np.full(len(everything), -1, dtype=np.int64)
        answer[mine] = start + np.asarray(self.displacement_dofs)[local[mine]]
        self.comm.Allreduce(MPI.IN_PLACE, answer, op=MPI.MAX)
        offset = sum(len(r) for r in requests[:self.comm.rank])
        return answer[offset:offset + len(dofs)]

    def _change_operators(self):
        """A' and P' of the current A and P (after a reassembly)."""
        if not self.change or self.change_current:
            return
        self.change.congruence(self.A, self.A_vi)
        if self.P_vi is not self.A_vi:
            self.change.congruence(self.P, self.P_vi)
        self.change_current = True

    def _to_vi(self, x):
        """x' = T x (x itself without a change of variables)."""
        if not self.change:
            return x
        self.change.forward(x, self.x_vi)
        return self.x_vi

    def distances(self, x):
        """The distance g - u.nu_F of each constraint at x."""
        return self.set.gap - self.set.sign * self._to_vi(x).getArray(readonly=True)[self.dofs]

    def active_set(self, x):
        """Constraints on the foundation to round-off: the active flag of
        state(), without the contact forces (collective)."""
        flags = _on_foundation(self.distances(x), self.displacement_scale(x))
        return ActiveSet(flags, self.comm.allreduce(int(np.sum(flags)), op=MPI.SUM))

    def state(self, x, b, pressure_out, active_out):
        """Contact force R = A x - b, in the new variables R' = T^{-T} R: the
        multiplier of each constraint; contact pressure -sign R'[dof] / lumped
        measure; a constraint is active on the foundation to round-off."""
        distance = self.distances(x)
        self.A.mult(x, self.force)
        self.force.axpy(-1.0, b)
        force = self.force
        if self.change:
            self.change.dual(self.force, self.b_vi)
            force = self.b_vi
        pressure = -self.set.sign * force.getArray(readonly=True)[self.dofs] / self.set.lumped
        s = ContactState()
        s.gap_scale = self.displacement_scale(x)
        self._summarise(s, pressure, distance, pressure_out, active_out)
        self._fault_states(s, x, force, distance, pressure)
        return s

    def _fault_states(self, s, x, force, distance, pressure):
        """The fault pairs' states and summaries from x, the contact forces
        R' = T^{-T}(A x - b) and the constraints' distances and pressures
        (collective)."""
        c = self.set
        summary_of = np.cumsum(c.faults) - 1  # of a fault's boundary
        s.faults = [FaultSummary(name) for name, fault in zip(c.boundaries, c.faults) if fault]
        if not s.faults:
            return
        X, R = self._to_vi(x).getArray(readonly=True), force.getArray(readonly=True)
        start = self.x_start
        if self.change:
            self.change.forward(self.x_start, self.x_start_vi)
            start = self.x_start_vi
        start = start.getArray(readonly=True)
        constraint = np.flatnonzero(c.pair_node >= 0)  # of each pair
        s.pairs = [self._pair_state(k, X, start, R, distance[k], pressure[k]) for k in constraint]
        scale = self._traction_scale(pressure, s.pairs)
        # Per fault: the largest opening and slip; the measures closed,
        # slipping and stuck, and the moment.
        largest, measure = np.zeros(2 * len(s.faults)), np.zeros(4 * len(s.faults))
        for p, k in zip(s.pairs, constraint):
            closed = bool(_on_foundation(distance[k], s.gap_scale))
            p.status = pair_status(c.laws[p.fault], PairTraction(closed, p.traction,
                                                                 math.hypot(*p.tangential_traction), scale))
            f = summary_of[p.fault]
            largest[2 * f] = max(largest[2 * f], p.opening)
            largest[2 * f + 1] = max(largest[2 * f + 1], math.hypot(*p.slip))
            measure[4 * f] += c.lumped[k] if closed else 0.0
            measure[4 * f + 1] += c.lumped[k] if p.status == PairStatus.slip else 0.0
            measure[4 * f + 2] += c.lumped[k] if p.status == PairStatus.stick else 0.0
            measure[4 * f + 3] += c.shear_modulus[k] * math.hypot(*p.slip_increment) * c.lumped[k]
        self.comm.Allreduce(MPI.IN_PLACE, largest, op=MPI.MAX)
        self.comm.Allreduce(MPI.IN_PLACE, measure, op=MPI.SUM)
        for f, summary in enumerate(s.faults):
            summary.max_opening, summary.max_slip = largest[2 * f], largest[2 * f + 1]
            summary.closed, summary.slipping, summary.stuck, summary.moment = measure[4 * f:4 * f + 4]

    def _pair_state(self, k, X, start, R, distance, pressure):
        """The state of the fault pair of constraint k but its status, from
        x' (X), x' at the start of the step (start) and R' (R)."""
        c, d = self.set, self.set.dim
        frame = c.pair_frame[k]
        p = PairState(int(c.pair_node[k]), int(c.boundary[k]), distance, pressure, np.zeros(3), np.zeros(3))
        # The + node's tangential rows r = 1..d-1 of x' = T x hold the jump's
        # tangential components in the pair's frame, w_J = R [u], and those
        # of R' the contact force on them (change_of_variables.py); R^T takes
        # both back to the global frame. The force becomes a traction as the
        # normal one does (state: -sign R'/lumped, sign +1 for a pair): the
        # traction the + face exerts on the - face, along the slip increment
        # when the pair slips (contact_law.py).
        for r in range(1, d):
            row = self.displacement_dofs[c.dofs[k] + r]
            p.slip[:d] += frame[r, :d] * X[row]
            p.slip_increment[:d] += frame[r, :d] * (X[row] - start[row])
            p.tangential_traction[:d] -= frame[r, :d] * R[row] / c.lumped[k]
        return p

    def _traction_scale(self, pressure, pairs):
        """The largest contact traction, normal or tangential, of the
        constraints on all ranks: the scale of the states' tolerance
        (collective)."""
        scale = np.abs(pressure).max(initial=0.0)
        for p in pairs:
            scale = max(scale, math.hypot(*p.tangential_traction))
        return self.comm.allreduce(scale, op=MPI.MAX)

    def _summarise(self, s, pressure, distance, pressure_out, active_out):
        """The diagnostics and output fields of the constraints' pressures
        and distances; a node on two foundations shows the larger pressure."""
        active = _on_foundation(distance, s.gap_scale)
        pressure_out.x.array[:] = 0.0
        active_out.x.array[:] = 0.0
        out = self.set.output_dofs
        pressure_out.x.array[out] = pressure
        np.maximum.at(pressure_out.x.array, out, pressure)
        np.maximum.at(active_out.x.array, out, active * 1.0)
        pressure_out.x.scatter_forward()
        active_out.x.scatter_forward()
        s.active_nodes = self.comm.allreduce(int(active.sum()), op=MPI.SUM)
        s.contact_nodes = self.comm.allreduce(len(self.dofs), op=MPI.SUM)
        s.max_penetration = self.comm.allreduce((-distance).max(initial=-np.inf), op=MPI.MAX)
        s.max_complementarity = self.comm.allreduce(np.abs(pressure * distance).max(initial=0.0), op=MPI.MAX)
        s.max_pressure = self.comm.allreduce(pressure.max(initial=-np.inf), op=MPI.MAX)
        s.min_pressure = self.comm.allreduce(pressure.min(initial=np.inf), op=MPI.MIN)
        force = 0.0  # sum of the nodal contact forces along -nu_F, summed in order as the C++
        for p_k, lumped in zip(pressure, self.set.lumped):
            force += p_k * lumped
        s.total_force = self.comm.allreduce(force, op=MPI.SUM)
        s.boundaries = []  # (name, sum of nodal contact forces along -nu_F, active constraints)
        for b, name in enumerate(self.set.boundaries):
            mine = self.set.boundary == b
            local = 0.0
            for p_k, lumped in zip(pressure[mine], self.set.lumped[mine]):
                local += p_k * lumped
            s.boundaries.append((name, self.comm.allreduce(local, op=MPI.SUM),
                                 self.comm.allreduce(int(active[mine].sum()), op=MPI.SUM)))
