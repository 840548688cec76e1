"""The bound-constrained problem the contact poses (contact.py) and its
solver (cpp/contact/variational_inequality.h): find y with l <= y <= u and
F(y) = K y - b complementary to the bounds, the frictional constraints'
tangential rows of F carrying the return map on the Coulomb disc
(friction.py). PETSc's reduced-space active-set Newton (SNES vinewtonrsls)
solves it, with the stopping rules of convergence.py. Without friction F is
linear and K its exact Jacobian."""
import contextlib
import dataclasses

import numpy as np
from mpi4py import MPI
from petsc4py import PETSc

from ..assembly.linear_algebra import set_lag_preconditioner
from .convergence import ContactConvergence, VIBounds
from .factorization_reuse import KrylovOnReuse, analyse_quickly, reuse_options
from .whole_system import solve_clamped
from .friction import FrictionPoint, add_friction_forces, friction_jacobian, friction_term, jacobian_weights
from ..solvers.field_split import is_coupled
from ..solvers.inactive_set_preconditioner import InactiveSetPreconditioner
from ..solvers.row_weights import BalancedRows
from ..solvers.shared_outcome import SolveOutcome, shared_outcome
from ..solvers.options import OptionsError, system_name
from ..solvers.linear_solver import set_relative_tolerance
from ..solvers.solver import (ITERATIVE_TOLERANCE, Method, SolverError, agreed_error, given_by_user,
                              petsc_error_text, reason_name, set_default_option, unsymmetric_jacobian_options)
from ..solvers.solver_statistics import SolverStatistics

# PETSc's error codes of a zero pivot (PETSC_ERR_MAT_LU_ZRPVT,
# PETSC_ERR_MAT_CH_ZRPVT), which petsc4py does not name.
_ZERO_PIVOTS = (71, 81)

# What a friction whose Newton iteration does not settle (no linear solve
# failed) may mean: a body that friction cannot hold, or contact states that
# the step changes too much at once (a spreading opening: docs/theory.md,
# "Newton on the cubic law"; a well into a closed fault, whose first steps
# must be short: test_fault_network).
NO_EQUILIBRIUM = (" (with friction: a body that friction cannot hold has no quasi-static equilibrium, or the step "
                  "is too long for the contact states to settle: time.retry halves it, time.adaptive chooses it)")


@dataclasses.dataclass
class VIProblem:
    """A VI as the contact poses it: its communicators (PETSc's and mpi4py's:
    the system's, or COMM_SELF when every rank solves the same small
    problem), options prefix and log stage (a SolverStage, or None), the
    prefix of the system it comes from (its messages), its matrix K and a
    vector like y; the bounded positions of y (local) with their gaps and
    signs, sign y <= gap; the frictional constraints in y's numbering, their
    tangents each (d - 1) and whether any rank has one; y's separate rows
    (convergence.py); and whether K changes in a few rows between most
    solves (the monolithic system with conduit faults: operator_nudged)."""
    comm: object
    mpi_comm: object
    prefix: str
    stage: object
    system_prefix: str
    K: PETSc.Mat
    layout: PETSc.Vec
    bounded: np.ndarray
    gap: np.ndarray
    sign: np.ndarray
    friction: list = dataclasses.field(default_factory=list)
    tangents: int = 0
    frictional: bool = False
    separate_rows: object = ()
    changing: bool = False
    shared: object = None  # ranks that each solve it alone (mpi4py): rank 0's outcome is theirs


class VariationalInequality:
    """The solver of a VIProblem (SNES vinewtonrsls), options-driven."""

    def __init__(self, problem, whole):
        """`whole` when the VI is posed on the whole system (None when it is
        on a condensed one). Raises OptionsError for options that make no VI
        solver."""
        self.p, self.whole = problem, whole
        self.y = problem.layout.duplicate()
        self.b, self.residual, self.lower, self.upper = (self.y.duplicate() for _ in range(4))
        # K y - b at the y of this SNES solve's last residual (_elastic_residual)
        self.elastic, self.elastic_at = self.y.duplicate(), self.y.duplicate()
        self.elastic_known = False
        # unbounded until solve() sets the contact bounds
        self.lower.set(PETSc.NINFINITY)
        self.upper.set(PETSc.INFINITY)
        self.scale = 1.0
        self.pins = np.zeros(0, dtype=np.int8)  # per bounded position (pin)
        self.newton_iterations = self.linear_iterations = 0
        self.J = self.y_reference = self.stiffness = self.preconditioner = None
        self.jacobian_weights = None  # J's as last built (jacobian_weights); None once K changed
        self.closed_when_clamped = []  # _record_clamped_states
        # 3D friction on the whole system, factorised: an earlier factorisation
        # preconditions GMRES (_reuse_factorization), in this solve until it fails
        self.reuse = self.reusing = False
        self.reuse_options = []
        if problem.frictional:
            self._make_friction_operators()
        if self.J is not None and whole is not None:
            unsymmetric_jacobian_options(problem.prefix)
        # a reduced system that CHOLMOD finds singular is answered by the
        # clamped start (_snes_solve): no warning on the terminal
        if whole is not None:
            set_default_option(problem.prefix + "mat_cholmod_print", "0")
        # condensed, the VI's unknown is the contact DOFs alone: no separate rows
        self.convergence = ContactConvergence(problem.mpi_comm, VIBounds(self.lower, self.upper, problem.bounded),
                                              problem.separate_rows)
        # the iterative coupled system's row weights (row_weights.py)
        self.balanced = None
        if whole is not None and whole.method == Method.iterative and is_coupled(whole.layout.fields):
            self.balanced = BalancedRows(problem.K, whole.layout.fields, problem.mpi_comm)
        self._create_snes()
        self._set_from_options()

    def load(self):
        """The load b, in the caller's units."""
        return self.b

    def unknown(self):
        """The unknown y (the start on entry to solve, the solution after)."""
        return self.y

    def slip_reference(self):
        """The start of the step in y's numbering: friction's slip increments
        are measured from it (None without friction)."""
        return self.y_reference

    def _make_friction_operators(self):
        """The Jacobian of friction and its vectors."""
        self.y_reference, self.stiffness = self.y.duplicate(), self.y.duplicate()
        self.y_reference.set(0.0)
        self.J = self.p.K.duplicate(copy=True)
        # its tangential rows are combinations of the constraint's own rows of
        # K (friction_jacobian), inside K's pattern where the rows of a node
        # share it; allowed to grow where they do not
        if self.whole is not None:
            self.J.setOption(PETSc.Mat.Option.NEW_NONZERO_ALLOCATION_ERR, False)
        self.J.setOption(PETSc.Mat.Option.SPD, False)
        self.J.setOption(PETSc.Mat.Option.SYMMETRIC, False)

    def _create_snes(self):
        """The semismooth Newton VI solver (SNES vinewtonrsls) and its
        defaults; the user's -<prefix>snes_* options override them."""
        prefix = self.p.prefix
        self.lag_by_default = not PETSc.Options().hasName(prefix + "snes_lag_preconditioner")
        self.snes_rtol_given = PETSc.Options().hasName(prefix + "snes_rtol")
        # The factorisation is built at the first Newton step, then reused
        # ("-2") until the inactive set changes (SNES VI resets it) or the
        # Jacobian does: K reassembled (operator_changed) or, with friction,
        # its rows' weights (_jacobian).
        # with friction (F semismooth: full steps can overshoot where a
        # constraint changes state) a backtracking search, but not with
        # separate rows: the search's merit ||F||, the forces' (N), is blind
        # to them (the coupled system's mass balances, m^3/s), whose step it
        # shrank to nothing
        backtrack = self.J is not None and not self.convergence.has_separate_rows()
        for option, value in (("snes_lag_preconditioner", "-2"), ("snes_rtol", "1e-10"),
                              ("snes_stol", "1e-12"), ("snes_max_it", "100"),
                              # F is linear, K exact: the full step is exact on the active
                              # set; with friction a backtracking search (above)
                              ("snes_linesearch_type", "bt" if backtrack else "basic"),
                              # no cap on the step's length (PETSc's 1e8): y is in units of
                              # the displacement scale, the coupled system's pressures run to
                              # 1e10 and more, and a capped step crawls
                              ("snes_linesearch_maxstep", "1e300")):
            set_default_option(prefix + option, value)
        self.snes = PETSc.SNES().create(self.p.comm)
        self.snes.setOptionsPrefix(prefix)
        self.snes.setType("vinewtonrsls")
        self.snes.setFunction(self._residual, self.residual)
        J = self.balanced.jacobian if self.balanced else self.J if self.J is not None else self.p.K
        self.snes.setJacobian(self._jacobian, J, J)
        self.snes.setVariableBounds(self.lower, self.upper)
        self.convergence.attach(self.snes, self._tested_load(), self.J is not None)
        self.convergence.measure_round_off(self.p.K, self.balanced.weights if self.balanced else None)
        # At least one Newton step per solve, so the result never lags the
        # load (not with friction: its F is not linear, the residual
        # decides, and a backtracking search fails on a zero step).
        self.snes.setForceIteration(not backtrack)

    def _set_from_options(self):
        """The preconditioner of the iterative method, then the user's options."""
        if self.whole is not None and self.whole.method == Method.iterative:
            self.convergence.watch(self.snes.getKSP())
            self.preconditioner = InactiveSetPreconditioner(self.snes, self.whole.P, self.whole.layout.fields,
                                                            self.balanced.weights if self.balanced else None,
                                                            self.whole.layout.prefix)
            self.set_tolerance(ITERATIVE_TOLERANCE)
        try:
            self.snes.setFromOptions()
        except PETSc.Error as e:
            raise OptionsError(f"the PETSc options of {system_name(self.p.system_prefix)} contact solver do not "
                               f"make a solver: {petsc_error_text(e)}") from None
        if self.whole is None or self.whole.method != Method.direct:
            return
        if self.p.tangents == 2 and (self.J is not None or self.p.changing):
            if self.lag_by_default and not given_by_user(self.p.prefix + "ksp_type"):
                self._reuse_factorization()
        elif self.p.changing or self.J is not None:
            # a 2D conduit fault's K changes at every solve, where GMRES on the
            # last factorisation took 15-30 back-solves a Newton step, more
            # than a factorisation with a quick analysis costs in 2D: each
            # change is factorised (docs/performance.md, "thirty-fourth
            # session"); friction's J changes with the inactive set and the
            # slip states, METIS's analysis took 2.1 of 10.6 s of the
            # 50-fracture network ("fortieth session")
            analyse_quickly(self.p.prefix, self.p.K)

    def _solver_name(self):
        """"the contact solver (SNES <type>)": the SNES type the options
        made, for the solver's errors."""
        return f"the contact solver (SNES {self.snes.getType()})"

    def _reuse_factorization(self):
        """In 3D a slipping pair's rows of J turn with its slip at every
        Newton step, and a conduit fault's rows of K follow its apertures
        from solve to solve, while the rest of K and the inactive set stay,
        and a factorisation costs about 100 back-solves: the factorisation
        of an earlier J preconditions GMRES on the new one (reuse_options),
        else the Jacobian is factorised anew (_refactorised; theory.md,
        "Friction")."""
        self.reuse = True
        self.reuse_options = reuse_options(self.p.prefix)

    def _krylov_on_reuse(self):
        """KrylovOnReuse while reusing a factorisation, else nothing."""
        return KrylovOnReuse(self.snes, self.reuse_options) if self.reuse else contextlib.nullcontext()

    def operator_changed(self):
        """K was reassembled: "rebuild once, then reuse" re-armed."""
        self.jacobian_weights = None
        if self.balanced:
            self.balanced.operator_changed()
        if self.lag_by_default:
            set_lag_preconditioner(self.snes, -2)

    def operator_nudged(self):
        """A few rows of K changed (a conduit fault's apertures): where an
        earlier factorisation is reused, it preconditions GMRES on the new K
        (friction's J is built from it); else as operator_changed."""
        if not self.reuse:
            return self.operator_changed()
        self.jacobian_weights = None

    def set_tolerance(self, relative):
        """Solves to `relative` (iterative): the Krylov and the Newton tolerance."""
        if not self.preconditioner:
            return
        set_relative_tolerance(self.snes.getKSP(), self.whole.layout.prefix, relative)
        if not self.snes_rtol_given:
            self.snes.setTolerances(rtol=relative)

    def preconditioner_setups(self):
        """Set-ups of the iterative preconditioner and their seconds (None otherwise)."""
        return (self.preconditioner.setups, self.preconditioner.setup_time) if self.preconditioner else None

    def factorizations(self):
        """The factorisations in the VI's own log stage (a condensed VI's; 0
        without a stage: the system's stage counts them)."""
        s = SolverStatistics()
        if self.p.stage:
            self.p.stage.read(s)
        return s.setups

    def solve(self, scale):
        """Solves in units of `scale` (SNES decides "on a bound" with an
        absolute tolerance of 1e-8; the residual K (y/s) - b/s has the same
        Jacobian K); retried from the clamped state when the first attempt
        fails. Raises SolverError when both do."""
        with self._krylov_on_reuse():
            reason = self._first_attempt(scale)
            if reason == PETSc.SNES.ConvergedReason.DIVERGED_LINEAR_SOLVE and self.reusing:
                reason = self._refactorised()
            if reason < 0:
                # A body held in the normal direction by the foundation alone
                # is semi-coercive: from a start where no contact DOF pushes on
                # its bound the reduced system is singular. Start again with
                # every contact node on the foundation; the contact forces
                # there say which nodes to release.
                self._clamped_start()
                self.convergence.continue_solve()
                reason = self._snes_solve()
                self._count(reason)
        if reason < 0:
            raise SolverError(f"{self._solver_name()} did not converge: "
                              + ("its Newton steps cycle between sets of contact states" if self.convergence.cycling
                                 else reason_name(PETSc.SNES.ConvergedReason, reason))
                              + (NO_EQUILIBRIUM if self.J is not None
                                 and reason != PETSc.SNES.ConvergedReason.DIVERGED_LINEAR_SOLVE else ""))
        self.y.scale(scale)

    def continue_from(self, earlier):
        """This solver goes on from `earlier` (another path's): the run's
        counts and its progress line."""
        self.newton_iterations, self.linear_iterations = earlier.newton_iterations, earlier.linear_iterations
        self.convergence.active_set_changes = earlier.convergence.active_set_changes
        self.convergence.on_newton_step = earlier.convergence.on_newton_step

    def pin(self, pins):
        """Per bounded position from the next solve on: 0 bounded as posed,
        1 pinned closed (both bounds at the gap), -1 pinned open (no bound);
        empty: all as posed (coupling/pins.py)."""
        self.pins = np.asarray(pins, dtype=np.int8)

    def set_friction(self, friction):
        """The frictional constraints anew, in the same positions (a law
        changed: a bond broke, or a new step restored the step's start)."""
        self.p.friction = friction
        self.jacobian_weights = None  # its bounds changed: J is built anew

    def _record_clamped_states(self):
        """closed_when_clamped of the clamped state y: per frictional
        constraint, whether it is closed (pressed on its bound,
        friction_term) with every bounded DOF on its bound and every
        frictional constraint stuck, a state that neither the path nor the
        laws change; empty without friction."""
        self.closed_when_clamped = []
        if self.J is None:
            return
        self.elastic_known = False
        self._elastic_residual(self.y)
        at = self._friction_point(self.y, self.elastic.getArray(readonly=True))
        self.closed_when_clamped = [friction_term(f, at).closed for f in self.p.friction]

    def _refactorised(self):
        """GMRES did not converge on an earlier factorisation: the solve goes
        on from its last iterate with J factorised whenever it changes."""
        self.reusing = False
        set_lag_preconditioner(self.snes, -2)
        reason = self._snes_solve()
        self._count(reason)
        return reason

    def try_solve(self, scale, newton_steps):
        """One attempt of at most `newton_steps` Newton steps, no clamped
        restart: whether it converged (y is then the solution; else y and the
        load are spent)."""
        max_it = self.snes.getTolerances()[3]
        self.snes.setTolerances(max_it=newton_steps)
        with self._krylov_on_reuse():
            reason = self._first_attempt(scale)
        self.snes.setTolerances(max_it=max_it)
        if reason < 0:
            return False
        self.y.scale(scale)
        return True

    def _first_attempt(self, scale):
        """One SNES solve from y, in units of `scale`."""
        self.scale = scale
        self.reusing = self.reuse
        self.b.scale(1.0 / scale)
        self.y.scale(1.0 / scale)
        if self.balanced:
            self.balanced.pose(self.p.K, self.J if self.J is not None else self.p.K, self.b)
        self._set_bounds()
        self._set_tolerances()
        if self.J is not None:  # the stiffness that turns a slip increment into a trial force
            self.p.K.getDiagonal(self.stiffness)
        reason = self._snes_solve()
        self._count(reason)
        return reason

    def _set_bounds(self):
        """sign y[dof] <= gap: y[dof] <= gap or y[dof] >= -gap, in units of
        the scale; a pinned position on both bounds (closed) or on none
        (open)."""
        p = self.p
        bound = p.sign * p.gap / self.scale
        pins = self.pins if len(self.pins) else np.zeros(len(p.bounded), dtype=np.int8)
        upper = np.where((p.sign > 0) & (pins >= 0) | (pins > 0), bound, PETSc.INFINITY)
        lower = np.where((p.sign < 0) & (pins >= 0) | (pins > 0), bound, PETSc.NINFINITY)
        with self.upper as up:
            up[p.bounded] = upper
        with self.lower as lo:
            lo[p.bounded] = lower

    def _set_tolerances(self):
        """The absolute tolerance relative to the load unless -snes_atol is
        given: scale-free; and the separate rows' by their own load."""
        if not PETSc.Options().hasName(self.p.prefix + "snes_atol"):
            # With friction the residual decides the last step (F is not
            # linear): tighter, Newton's last steps are quadratic.
            relative = 1e-12 if self.J is not None else 1e-10
            self.snes.setTolerances(atol=max(relative * self._tested_load().norm(), 1e-300))
        self.convergence.pose()

    def _count(self, reason):
        """Every attempt's steps count, a failed Krylov solve's iterations
        too (SNES leaves them out of its own count)."""
        failed = self.snes.getKSP().getIterationNumber() \
            if reason == PETSc.SNES.ConvergedReason.DIVERGED_LINEAR_SOLVE else 0
        self.newton_iterations += self.snes.getIterationNumber()
        self.linear_iterations += self.snes.getLinearSolveIterations() + failed

    def _snes_solve(self):
        self.elastic_known = False  # b, K and the scale are the solve's own
        outcome, error = SolveOutcome(), None
        try:
            with self.p.stage or contextlib.nullcontext():
                self.snes.solve(None, self.y)
        except PETSc.Error as e:
            error = e
        # one path on every rank: a failure may be one rank's
        if (e := agreed_error(error, self.snes.getComm())) is None:
            outcome.reason = self.snes.getConvergedReason()
        elif e.ierr in _ZERO_PIVOTS:
            # a zero pivot in the factorisation of a Newton step's reduced
            # system: the system is singular (a body that the contact alone
            # holds, from a start that presses on nothing), a failed step as
            # DIVERGED_DTOL is (convergence.py), which the clamped start answers
            outcome.reason = PETSc.SNES.ConvergedReason.DIVERGED_LINEAR_SOLVE
        else:
            outcome.failure = f"{self._solver_name()} failed: {petsc_error_text(e)}"
        if self.p.shared is not None:
            outcome = shared_outcome(outcome, self.y, self.p.shared)
        if outcome.failure:
            raise SolverError(outcome.failure) from None
        return outcome.reason

    def _clamped_start(self):
        """Every bounded DOF on its bound and, with friction, every
        frictional constraint stuck (its tangential unknowns at the step's
        start); the other DOFs (none when condensed) solve A y = b/s with
        the clamped rows and columns eliminated and the known values moved
        to the right-hand side. Tangential unknowns left free would slide
        the faces as if frictionless, a start from which every pair looks
        slipping (theory.md, "Friction")."""
        p = self.p
        up, lo = self.upper.getArray(readonly=True), self.lower.getArray(readonly=True)
        stuck = np.array([f.tangential[q] for f in p.friction for q in range(p.tangents)], dtype=np.int64)
        with self.y as y:
            y[p.bounded] = np.where(p.sign > 0, up[p.bounded], lo[p.bounded])
            if stuck.size:
                y[stuck] = self.y_reference.getArray(readonly=True)[stuck] / self.scale
        if self.whole is not None:
            clamped = np.concatenate([p.bounded, stuck])
            solve_clamped(self.whole, self.b, self.y, (self.y.getOwnershipRange()[0] + clamped).astype(PETSc.IntType))
        self._record_clamped_states()

    def _residual(self, snes, y, F):
        """F(y) = K y - b/s: the gradient of the quadratic energy, in units
        of s; with friction its frictional constraints' tangential rows carry
        the return map (friction.py); W F with balanced rows."""
        self._elastic_residual(y)
        self.elastic.copy(F)
        if self.J is not None:
            with F as R:
                add_friction_forces(self.p.friction, self._friction_point(y, R), R)
        if self.balanced:
            F.pointwiseMult(F, self.balanced.weights)

    def _jacobian(self, snes, y, J, P):
        """The constant matrix K (A, or H formed once per A); with friction
        the generalised Jacobian of its rows (friction_jacobian), built anew,
        and its factorisation with it, only when its rows' weights changed
        (on every rank alike: the factorisation is collective). The
        iterative path's preconditioner is built from P and the inactive set
        alone, not from J."""
        if self.J is None:
            return
        self._elastic_residual(y)
        at = self._friction_point(y, self.elastic.getArray(readonly=True))
        weights = jacobian_weights(self.p.friction, at)
        if self.p.mpi_comm.allreduce(weights == self.jacobian_weights, op=MPI.LAND):
            return
        friction_jacobian(self.p.friction, at, self.p.K, self.J)
        self.jacobian_weights = weights
        if self.lag_by_default and self.preconditioner is None and not self.reusing:
            set_lag_preconditioner(snes, -2)
        if self.balanced:
            self.balanced.weigh_jacobian(self.J)

    def _elastic_residual(self, y):
        """K y - b into self.elastic, unless it holds that of this very y
        already: SNES asks for the Jacobian at the point whose residual it
        evaluated last (a product with K less per Newton step, where the
        condensed K is dense: m^2 per product). Equal bit for bit or computed
        anew."""
        if self.elastic_known and y.equal(self.elastic_at):
            return
        self.p.K.mult(y, self.elastic)
        self.elastic.axpy(-1.0, self.b)
        y.copy(self.elastic_at)
        self.elastic_known = True

    def _tested_load(self):
        """The load the convergence tests measure: b, or W b with balanced rows."""
        return self.balanced.load if self.balanced else self.b

    def _friction_point(self, y, R):
        """Friction at y with the residual R = K y - b (friction.py)."""
        return FrictionPoint(y.getArray(readonly=True), R, self.y_reference.getArray(readonly=True),
                             self.stiffness.getArray(readonly=True), self.scale, self.p.tangents)
