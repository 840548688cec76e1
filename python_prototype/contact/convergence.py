"""The stopping rules of the contact VI's Newton iteration (SNES
vinewtonrsls; cpp/contact/convergence.h): PETSc's residual test, the
primal-dual active set rule "the step kept its active set", a separate test
for rows in other units than the forces, and the Krylov stagnation of a
singular reduced system."""
import dataclasses

import numpy as np
from mpi4py import MPI
from petsc4py import PETSc

from ..solvers.backward_error import absolute_product

# The stopping rule of a repeated active set holds where the step has brought
# the residual below this fraction of the larger of the solve's first and
# the load.
REPEATED_SET_FRACTION = 1e-3
# With friction a residual at its round-off (residual_round_off) ends the
# solve where it lies below this fraction of the load.
ROUND_OFF_CEILING = 1e-8
# With friction, a Newton step that lifts the residual above this multiple of
# the larger of the solve's first residual and the load has met a singular
# reduced system (a piece the open pairs leave free): its steps wander
# without bound, and the solve ends.
DIVERGENCE_RATIO = 1e6


# With friction, a solve whose residuals repeat a cycle of at most
# LONGEST_NEWTON_CYCLE values for CYCLE_PERIODS periods cycles between sets of
# contact states (network3d's monolithic step at 0.5 m^3/s: nine values).
CYCLE_PERIODS = 3
LONGEST_NEWTON_CYCLE = 12


# With friction, a first attempt whose last STALL_STEPS Newton steps each
# reduced the residual by less than STALL_REDUCTION of it has stalled: its
# line search finds no descent along the semismooth direction, and the
# clamped start follows.
STALL_STEPS = 3
STALL_REDUCTION = 1e-3


def newton_stall(norms, steps):
    """Whether each of the last `steps` steps of `norms` reduced the norm by
    less than STALL_REDUCTION of it."""
    n = len(norms)
    if steps == 0 or n < steps + 1:
        return False
    return all(norms[k] > (1 - STALL_REDUCTION) * norms[k - 1] for k in range(n - steps, n))


def _same_norm(a, b):
    """Two residual norms equal to 1e-9 (the last digits of a repeated
    iterate)."""
    return abs(a - b) <= 1e-9 * max(a, b)


def rejoins_attempt(norms, attempt):
    """Whether a clamped start's residuals `norms` (its start, then its first
    step) rejoin those of the first attempt it follows, `attempt`: its first
    step's residual equals the attempt's first step's to 1e-9."""
    return len(norms) == 2 and len(attempt) >= 2 and _same_norm(norms[1], attempt[1])


def newton_cycle(norms, periods):
    """Whether the last `periods` periods of `norms` repeat a cycle of L
    values for some L from 2 to LONGEST_NEWTON_CYCLE: each equal to the one L
    before it to 1e-9, and not all the same (stagnation is no cycle)."""
    n = len(norms)
    for length in range(2, LONGEST_NEWTON_CYCLE + 1):
        if periods < 1 or n < length * periods:
            break
        first = n - length * periods
        if (all(_same_norm(norms[k], norms[k - length]) for k in range(first + length, n))
                and any(not _same_norm(norms[k], norms[k - 1]) for k in range(first + 1, n))):
            return True
    return False


def residual_round_off(K, weights, y, b, r):
    """r = eps (W |K| |y| + |b|): a bound of the round-off of each entry of
    W (K y - b) (eps the machine's; W the row weights, None for none;
    collective)."""
    absolute_product(K, y, r)
    magnitude = b.duplicate()
    if weights is not None:
        r.pointwiseMult(r, weights)
    b.copy(magnitude)
    magnitude.abs()
    r.axpy(1.0, magnitude)
    r.scale(np.finfo(float).eps)
    magnitude.destroy()


@dataclasses.dataclass
class VIBounds:
    """The bounds of a VI's unknown: its lower and upper bound vectors, and
    the positions (local, in its numbering) that carry a bound."""
    lower: PETSc.Vec
    upper: PETSc.Vec
    bounded: np.ndarray


class ContactConvergence:
    """When a Newton iteration of the contact VI F(x) = K x - b (+ the
    friction forces) complementary to the bounds has converged, as SNES's
    monitor, convergence test and (iterative) Krylov monitor.

    The residual's norm is the forces' (N): SNES's norm less the rows in
    other units (the mass balances of the monolithic system, m^3/s), the
    `separate_rows`, whose residual is judged against their own load."""
    # A Krylov solve of a Newton step that reduces its residual by less than
    # 1% over this many iterations has stagnated (_stagnation).
    stagnation_window = 50

    def __init__(self, comm, bounds, separate_rows):
        """`comm` is the VI's (an mpi4py communicator); `separate_rows` local
        rows of its unknown."""
        self.comm, self.bounds = comm, bounds
        self.separate_rows = np.asarray(separate_rows, dtype=np.int32)
        self.any_separate = comm.allreduce(len(self.separate_rows), op=MPI.SUM) > 0
        self.snes = self.load = None
        self.friction = False
        self.continuing = False  # continue_solve() until the next first test
        self.continued = False  # the current solve continues a failed attempt
        self.operator = self.weights = None  # measure_round_off
        self.round_off_bound = 0.0  # ROUND_OFF_CEILING times the load
        self.pending = self.used = None  # active flags of the bounded DOFs
        self.set_repeated, self.relative_target, self.repeated_set_bound = False, 0.0, 0.0
        self.steps_exact = True  # a step solves its set: a factorisation, or Krylov to rtol (_start)
        self.divergence_bound = 0.0  # DIVERGENCE_RATIO times the first residual or the load
        # the residual on the separate rows is small below the larger of
        # these: their load's times the relative tolerance (pose), and rtol
        # times the solve's first
        self.separate_tolerance, self.separate_relative_target = 0.0, 0.0
        self.separate_met = False  # this solve's separate rows met their tolerance once
        self.residuals, self.lowered_from = [], 0  # of the current Krylov solve (_stagnation)
        # Newton steps whose inactive set differed from the previous step's
        # (across solves): each may cost one factorisation.
        self.active_set_changes = 0
        self.on_newton_step = None  # called after each Newton step with its number
        self.norms = []  # of the current Newton solve (newton_cycle)
        self._attempt = []  # the failed first attempt's, in a clamped start
        self._attempt_cycled = False  # whether it ended in a cycle
        # with friction, the last solve was stopped because its residuals
        # repeated a cycle for CYCLE_PERIODS periods (newton_cycle;
        # its reason DIVERGED_DTOL)
        self.cycling = False

    def has_separate_rows(self):
        """Whether any rank has separate rows (collective, at construction)."""
        return self.any_separate

    def attach(self, snes, load, friction):
        """Tests `snes`'s steps, with `load` the VI's b (as posed);
        `friction`: F is not linear."""
        self.snes, self.load, self.friction = snes, load, friction
        snes.setConvergenceTest(self._converged)
        snes.setMonitor(self._monitor)

    def watch(self, ksp):
        """Stops a Krylov solve of a Newton step that stagnates."""
        ksp.setMonitor(self._stagnation)

    def pose(self):
        """The load has been posed: the separate rows' tolerance from it
        (with friction tighter, as the forces' absolute tolerance)."""
        self.separate_tolerance = (1e-12 if self.friction else 1e-10) * self._separate_norm(self.load)

    def measure_round_off(self, K, weights):
        """With friction, a residual at the round-off of K y - b (weighted by
        `weights`, None for none) ends the solve (_converged)."""
        self.operator, self.weights = K, weights

    def continue_solve(self):
        """The next SNES solve continues the last one (the clamped start
        after a failed first attempt): with friction it keeps that one's
        targets."""
        self.continuing = True

    def active_contact_dofs(self, x):
        """PETSc's rule (SNESVIGetActiveSetIS): on a bound to 1e-8, pushed
        against it; and whether a DOF lies on a bound that F does not push
        (clipped): the projection put it there after a step that left it
        free, so that step did not solve its equation."""
        X, F = x.getArray(readonly=True), self.snes.getFunction()[0].getArray(readonly=True)
        lo, up = self.bounds.lower.getArray(readonly=True), self.bounds.upper.getArray(readonly=True)
        i = self.bounds.bounded
        on_lower, on_upper = X[i] <= lo[i] + 1e-8, X[i] >= up[i] - 1e-8
        active = (on_lower & (F[i] > 0)) | (on_upper & (F[i] < 0))
        return active, bool(np.any((on_lower | on_upper) & ~active))

    def _monitor(self, snes, iteration, norm):
        """Before each Newton step (and after the last): the set the next step uses."""
        if iteration > 0:
            changed = self.used is not None and not np.array_equal(self.pending, self.used)
            self.active_set_changes += int(self.comm.allreduce(int(changed), op=MPI.MAX))
            self.used = self.pending
        self.pending, clipped = self.active_contact_dofs(snes.getSolution())
        if iteration > 0:
            differs = not np.array_equal(self.pending, self.used) or clipped
            self.set_repeated = not self.comm.allreduce(int(differs), op=MPI.MAX)
            if self.on_newton_step is not None:
                self.on_newton_step(iteration)

    def _stagnation(self, ksp, iteration, rnorm):
        """A Newton step's Krylov solve that reduces its residual by less than
        1% over the last stagnation_window iterations (a singular reduced
        system, a round-off right-hand side) is stopped: its iteration limit
        is lowered to now (DIVERGED_ITS) and restored at the next solve;
        the contact solve restarts from the clamped state (cpp/contact/convergence.cpp)."""
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

    def _start(self, snes, fnorm, rtol):
        """A solve's first residual sets its relative targets."""
        # with friction F is not linear, and a start far off (the clamped
        # start of a body that slides) would make any residual "relative":
        # relative to the load then, where that is smaller
        load = self.load.norm()
        self.relative_target = rtol * min(fnorm, load if self.friction else fnorm)
        # a step that left the residual above a fraction of the first (or of
        # the load, where the start was close) did not solve F = 0 on its
        # set (a singular reduced system: a body held by the contact alone,
        # from a start that presses on nothing)
        self.repeated_set_bound = REPEATED_SET_FRACTION * max(fnorm, load)
        self.divergence_bound = DIVERGENCE_RATIO * max(fnorm, load)
        # the active set method's rule trusts a step to solve its set: a
        # factorisation's, or a Krylov solve as tight as rtol (the project
        # ties the two); with a looser -<prefix>ksp_rtol (0.5 on hertz: the
        # set repeated at 4e-4 of the first residual, the contact pressure
        # 6 % off, exit 0) the residual tests decide
        ksp = snes.getKSP()
        self.steps_exact = ksp.getType() == PETSc.KSP.Type.PREONLY or ksp.getTolerances()[0] <= rtol
        self.round_off_bound = ROUND_OFF_CEILING * load
        self.separate_relative_target = rtol * self._separate_norm(snes.getFunction()[0])
        self.separate_met = False

    def _converged(self, snes, iteration, norms):
        """PETSc's test of the VI methods after at least one step, and the
        stopping rule of the primal-dual active set method: the step kept its
        active set, so x solves the VI even where the residual's round-off
        lies above atol (cpp/contact/convergence.cpp). With friction F is
        not linear: only the residual says when it is solved."""
        _, _, fnorm = norms
        rtol, atol, _, _ = snes.getTolerances()
        # with friction the clamped start continues the solve whose first
        # attempt failed, with that attempt's targets: from the clamped
        # start's own residual (on a fine fracture network 2.5e-11 of the
        # load, every pair stuck as in the solution) rtol would ask for less
        # than the residual's round-off. Frictionless, F is linear and the
        # repeated active set ends the solve at round-off.
        if iteration == 0:
            self.continued, self.continuing = self.continuing and self.friction, False
            self._attempt = self.norms if self.continued else []
            self._attempt_cycled = self.continued and self.cycling
            self.norms, self.cycling = [], False
            if not self.continued:
                self._start(snes, fnorm, rtol)
        forces, separate_part = self._split_norm(fnorm)
        separate = self._separate_may_stop(self._separate_solved(iteration, separate_part))
        reasons = PETSc.SNES.ConvergedReason
        if not np.isfinite(fnorm):
            return reasons.DIVERGED_FNORM_NAN
        # a step taken, or the start with friction
        if (iteration > 0 or self.friction) and forces < atol and separate:
            return reasons.CONVERGED_FNORM_ABS
        if iteration > 0 and forces < self.relative_target and separate:
            return reasons.CONVERGED_FNORM_RELATIVE
        # with friction the residual's round-off (each force row's eps sum_j
        # |K_ij y_j|, stiff rows of small cells) can lie above atol and a
        # coupling iteration's relative target: on a fine fracture network
        # the Newton steps jittered at 5e-12 of the load until the line
        # search failed. A residual within it is solved, if below
        # ROUND_OFF_CEILING of the load.
        if self.friction and iteration > 0 and separate and forces < self.round_off_bound \
                and self._at_round_off(forces):
            return reasons.CONVERGED_FNORM_ABS
        if iteration > 0 and self.set_repeated and not self.friction and self.steps_exact:
            if fnorm <= self.repeated_set_bound:
                return reasons.CONVERGED_ITS
            # above both refused at once (the solver starts again clamped),
            # else iterated on
            if fnorm > self.repeated_set_bound / REPEATED_SET_FRACTION:
                return reasons.DIVERGED_DTOL
        if self.friction:
            return self._newton_path(fnorm)
        return reasons.CONVERGED_ITERATING

    def _newton_path(self, fnorm):
        """With friction, after a step that met no test: DIVERGED_DTOL where
        the solve cycles (newton_cycle) or its first attempt stalls
        (newton_stall), else CONVERGED_ITERATING."""
        reasons = PETSc.SNES.ConvergedReason
        self.norms.append(fnorm)
        # a semismooth Newton step is exact on its contact states: two states
        # each of whose steps lands in the other repeat the same two iterates,
        # and their residuals, to the last digits (friction's kink at a pair
        # with t_N = 0: Phan's crack loaded at once on the coupled system)
        if newton_cycle(self.norms, CYCLE_PERIODS):
            self.cycling = True
            return reasons.DIVERGED_DTOL
        # test_fault_network's star fed by a well of 1e-2 m^2/s at dt = 1 s:
        # the clamped start's residual reached 1e22 from 1e7 and wandered for
        # 100 steps, each a factorisation
        if fnorm > self.divergence_bound:
            return reasons.DIVERGED_DTOL
        # a first attempt whose line search shrinks every step to nothing (the
        # 50-fracture network's initial equilibrium on 2 ranks) ends, and the
        # clamped start, whose pairs all stick, goes on from there
        if not self.continued and newton_stall(self.norms, STALL_STEPS):
            return reasons.DIVERGED_DTOL
        # a clamped start whose first step lands where the first attempt's
        # did retraces that attempt (the step depends on its iterate alone),
        # whose verdict stands: found no other path (the onset of
        # test_cohesive_opening on the coupled system)
        if self.continued and rejoins_attempt(self.norms, self._attempt):
            self.cycling = self._attempt_cycled
            return reasons.DIVERGED_DTOL
        return reasons.CONVERGED_ITERATING

    def _round_off_norms(self):
        """The norms of residual_round_off at the current unknown on the
        force rows and on the separate rows (collective)."""
        y = self.snes.getSolution()
        r = y.duplicate()
        residual_round_off(self.operator, self.weights, y, self.load, r)
        total, separate = r.norm(), self._separate_norm(r)
        r.destroy()
        return np.sqrt(max(total ** 2 - separate ** 2, 0.0)), separate

    def _at_round_off(self, fnorm):
        """Whether the residual's norm `fnorm` on the force rows lies within
        the round-off of the solve's operator at its current unknown
        (collective)."""
        return self.operator is not None and fnorm <= self._round_off_norms()[0]

    def _separate_norm(self, v):
        """The norm of v on the separate rows (collective)."""
        rows = v.array_r[self.separate_rows]
        return float(np.sqrt(self.comm.allreduce(float(np.sum(rows ** 2)), op=MPI.SUM)))

    def _split_norm(self, fnorm):
        """SNES's residual norm `fnorm` split into the force rows' and the
        separate rows' (collective). The tests in N (atol, the relative
        target, the round-off) are the force rows': fnorm holds the separate
        rows too, whose own round-off can lie above atol
        (cpp/contact/convergence.cpp)."""
        separate = self._separate_norm(self.snes.getFunction()[0])
        return np.sqrt(max(fnorm ** 2 - separate ** 2, 0.0)), separate

    def _separate_solved(self, iteration, norm):
        """Whether the residual, of norm `norm` on the separate rows, is
        small there: below their tolerances or, with friction, within their
        round-off (collective)."""
        if norm <= self.separate_tolerance or (iteration > 0 and norm <= self.separate_relative_target):
            return True
        # with friction their tolerances can lie below their own round-off:
        # the undrained first step of a conduit in an impermeable rock has a
        # load of 2e-7 m^2/s on them (tolerance 2e-19) against exchanges of
        # 1e-3 that cancel, the residual 1.4e-14 and its round-off 5.7e-14,
        # where the Newton steps jittered to their limit
        return self.friction and iteration > 0 and self.operator is not None \
            and norm <= self._round_off_norms()[1]

    def _separate_may_stop(self, met):
        """Whether a solve whose separate rows are solved (`met`) may stop:
        with friction and separate rows, only one Newton step after they
        were first met in this solve (a separate row's tolerance lies far
        above its round-off where its load holds terms that cancel at the
        solution; cpp/contact/convergence.cpp)."""
        if not met or not (self.friction and self.any_separate):
            return met
        was, self.separate_met = self.separate_met, True
        return was
