"""Signorini contact against rigid foundations of any normal nu_F and
between a fault's faces (alg. "Mechanics with frictionless Signorini
contact"; friction: contact_law.py; cpp/contact/contact.h), for the
mechanics and the monolithic systems alike. The energy is quadratic: with
A the system matrix and b its load, each constraint u.nu_F <= g_a is a
bound on one DOF of x' = T x (change_of_variables.py), and the contact is
the variational inequality of variational_inequality.py on
(A' = T^-T A T^-1, b' = T^-T b), or on the Schur complement of its contact
DOFs (schur_complement.py).
"""
import dataclasses

import numpy as np
from mpi4py import MPI
from petsc4py import PETSc

from ..assembly.linear_algebra import solved_positions
from .change_of_variables import ChangeOfVariables
from .contact_law import on_foundation
from .contact_pins import ContactPins
from .contact_path import ContactPath, PathCosts, choose_contact_path
from .contact_state import (ActiveSet, ContactFields, ContactMeasurement, contact_pressures, contact_state,
                            junction_jumps)
from .friction import FrictionalConstraint, all_gather_constraints
from .load_continuation import CONTINUATION_SOLVES, SolvedLoad, continue_load
from .bonds import BondFailure, bonds_from_names, break_open_bonds, break_pulled_bonds, broken_bond_names
from .contact_set import any_frictional, constraint_law, displacement_scale
from .schur_complement import SchurComplement
from .variational_inequality import VariationalInequality, VIProblem
from .whole_system import WholeSystem
from ..solvers.solver import SolverError, Structure, SystemLayout, set_default_option
from ..solvers.solver_statistics import SolverStage


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
    # Whether the run solves the contact once (one step of the mechanics
    # alone): then by default the whole system's first Newton step (two
    # with friction) is tried before the condensed path (contact_path).
    once: bool = False


@dataclasses.dataclass
class ContactUnknowns:
    """What the contact solver constrains: the ContactSet, where each owned
    DOF of V sits in the solved vector (`displacement_dofs`: i itself for the
    mechanics system, its place in the mixed space for the monolithic one),
    and its separate rows (local): rows in other units than the forces,
    whose residual is judged by their own load (convergence.py)."""
    set: object
    displacement_dofs: object
    separate_rows: object = ()


class ContactSolver(ContactPins):
    """The VI as a bound-constrained problem: l <= x <= g with F(x) = A x - b
    complementary to the bounds, bounds only on the contact DOFs. The energy
    is quadratic: A is the exact (constant) Jacobian. SNESVI decides "on the
    bound" with an absolute tolerance (1e-8), so it solves for x/s with s the
    displacement scale (largest gap or |x|): F = A (x/s) - b/s.

    As in cpp/contact/contact.h it runs condensed (by default with a direct solver
    and at most MAX_CONDENSED_DOFS contact DOFs: SNES on the dense Schur
    complement H of A on the contact DOFs, options prefix <prefix>contact_,
    the large matrix factorised once with the contact DOFs clamped) or full
    (SNES on A, the inactive-set factorisation reused while the set stays
    the same; operator_changed re-arms it after a reassembly)."""

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
        self.dofs = self.displacement_dofs[self.set.dofs] if len(self.set.dofs) else np.zeros(0, dtype=np.int32)
        # The bonds as of now (set.bonded) and as of the last accepted step.
        self.set.bonded = np.ones(len(self.dofs), dtype=bool)
        self.bonded_accepted = self.set.bonded.copy()
        self.solved = SolvedLoad()  # the last load solved, where a failed solve's continuation starts
        self.force = A.createVecRight()
        # The start of the step like x, and x' of it (the faults' slip increments).
        self.x_start, self.x_start_vi = A.createVecRight(), A.createVecRight()
        self.x_start.set(0.0)
        self._make_change_of_variables()
        self.schur, self.schur_current = None, False
        costs = PathCosts(method, comm.allreduce(len(self._contact_dofs()), op=MPI.SUM), operators.changing,
                          operators.once)
        choice = choose_contact_path(comm, prefix, costs)
        path = choice.path
        # On the whole system until its first Newton step, or first two with
        # friction, fail to solve the VI (ContactOperators.once); a failed full
        # solve solved again condensed (ContactPathChoice); `after` says when
        # the path turned condensed ("" from the start).
        self.then_condensed = path == ContactPath.full_then_condensed
        self.condensed_on_failure, self.after = choice.condensed_on_failure, ""
        self.full_steps = 1
        if path == ContactPath.condensed:
            self.vi = self._condensed_vi()
        else:
            problem = self._pose_on_full_system(unknowns.separate_rows)
            problem.changing = operators.changing
            self._add_friction(problem)
            # Friction's stick and slip settle in a second Newton step (Phan's
            # crack: two full steps, where condensing after one added the
            # Schur complement to them; docs/schemes.md, "Faults").
            self.full_steps = 2 if problem.frictional else 1
            self.vi = VariationalInequality(problem, WholeSystem(comm, self.A_vi, self.P_vi,
                                                                 SystemLayout(prefix, structure, self.fields), method))

    def _condensed_vi(self):
        """The condensed VI, friction added."""
        problem = self._condense()
        self._add_friction(problem)
        return VariationalInequality(problem, None)

    def _switch_to_condensed(self, after):
        """The full path's trial or solve did not converge: the VI is posed
        condensed from now on, the counts carried over; `after` says when
        (method()). Returns the full path's VI."""
        vi, full = self._condensed_vi(), self.vi
        vi.continue_from(full)
        self.vi, self.then_condensed, self.condensed_on_failure, self.after = vi, False, False, after
        # friction's slip increments are measured from the step's start
        reference = self.vi.slip_reference()
        if reference is not None:
            with reference as r:
                r[:] = self.schur.restrict_to_contact(self._start_vi())
        return full

    def _back_to_full(self, full):
        """A failed full solve went on condensed and failed there too: the
        full path (its VI `full`, the one _switch_to_condensed returned)
        again."""
        full.continue_from(self.vi)
        self.vi, self.schur, self.schur_current, self.condensed_on_failure, self.after = full, None, False, True, ""

    def _condense(self):
        """The VIProblem on the Schur complement H = C A^-1 C^T of the
        contact DOFs (schur_complement.py): every unknown of the small dense
        problem is bounded but the tangential ones of friction."""
        dofs = self._contact_dofs()
        self.schur = SchurComplement(self.comm, self.prefix, self.A_vi, self.structure, dofs)
        # Each rank's constraints come first among its contact DOFs, its
        # tangential ones (friction) after them: the bounded DOFs of H are the
        # constraints'.
        bounded, gap, sign = np.zeros(len(dofs)), np.zeros(len(dofs)), np.zeros(len(dofs))
        n = len(self.dofs)
        bounded[:n], gap[:n], sign[:n] = 1.0, self.set.gap, self.set.sign
        kept = np.flatnonzero(self.schur.gather(bounded) > 0)
        # H is small and dense: LAPACK's factorisation, Cholesky when A is SPD
        # but for the Jacobian of friction, which is not symmetric.
        vi_prefix = self.prefix + "contact_"
        set_default_option(vi_prefix + "ksp_type", "preonly")
        symmetric = self.structure == Structure.spd and not any_frictional(self.set, self.comm)
        set_default_option(vi_prefix + "pc_type", "cholesky" if symmetric else "lu")
        set_default_option(vi_prefix + "pc_factor_mat_solver_type", "petsc")
        # every rank solves the same small problem
        return VIProblem(PETSc.COMM_SELF, MPI.COMM_SELF, vi_prefix, SolverStage(self.prefix + "contact"), self.prefix,
                         self.schur.H, PETSc.Vec().createSeq(self.schur.size(), comm=PETSc.COMM_SELF),
                         kept.astype(np.int32), self.schur.gather(gap)[kept], self.schur.gather(sign)[kept],
                         shared=self.comm)

    def _contact_dofs(self):
        """The contact DOFs of the VI: each constraint's, then the tangential
        ones of the frictional constraints."""
        c = self.set
        tangential = [self.displacement_dofs[c.dofs[k] + r] for k in range(len(self.dofs))
                      if c.frictional[k] for r in range(1, c.dim)]
        return np.concatenate([self.dofs, np.array(tangential, dtype=np.int32)])

    def _add_friction(self, problem):
        """The frictional constraints, once the VI is posed."""
        problem.friction = self._frictional_constraints()
        problem.tangents, problem.frictional = self.set.dim - 1, any_frictional(self.set, self.comm)

    def _frictional_constraints(self):
        """The frictional constraints in the VI's numbering, with their laws
        as the bonds are now: on the full system this rank's, at their local
        positions; condensed, every rank's at their places in H (each rank's
        contact DOFs from its offset, in _contact_dofs()'s order), gathered
        to every rank."""
        c, d = self.set, self.set.dim
        first = self.schur.offset if self.schur else 0
        mine = []
        following = len(self.dofs)  # the place of the next tangential DOF among this rank's
        for k in range(len(self.dofs)):
            if not c.frictional[k]:
                continue
            f = FrictionalConstraint(int(first + k if self.schur else self.dofs[k]), [-1, -1], float(c.sign[k]),
                                     float(c.gap[k]), float(c.lumped[k]), constraint_law(c, k))
            for r in range(1, d):
                f.tangential[r - 1] = int(first + following if self.schur else self.displacement_dofs[c.dofs[k] + r])
                following += 1
            mine.append(f)
        return all_gather_constraints(mine, self.comm) if self.schur else mine

    def _break_pulled_bonds(self):
        """After a failed solve: the bonds of the cohesive constraints its
        clamped start pulls break; whether any did (collective)."""
        # decided alike on every rank (_update_bonds is collective): a rank
        # without frictional constraints of its own has no flags (the full
        # path) but still takes part
        if not self.vi.p.frictional:
            return False
        closed = self.vi.closed_when_clamped
        # the VI's constraints: this rank's, or condensed every rank's in rank order
        mine = int(np.count_nonzero(self.set.frictional))
        first = (self.comm.exscan(mine) or 0) if self.schur else 0
        return self._update_bonds(break_pulled_bonds(self.set, closed, first))

    def _update_bonds(self, changed):
        """The VI takes the bonds as they are now, if they changed on any
        rank; whether they did (collective)."""
        changed = self.comm.allreduce(bool(changed), op=MPI.LOR)
        if changed:
            self.vi.set_friction(self._frictional_constraints())
        return changed

    def accept_step(self, x):
        """The step (or window) ending at x was accepted: the bonds of the
        pairs open at x break, and the bonds as they are now hold from the
        next step on (contact_law.py; collective)."""
        broke = break_open_bonds(self.set, self.active_set(x).flags)
        self.bonded_accepted = self.set.bonded.copy()
        self._update_bonds(broke)

    def broken_bonds(self):
        """The names (constraint_keys) of the constraints whose cohesion held
        and broke by the last accepted step, on every rank, for a checkpoint
        (collective)."""
        return broken_bond_names(self.set, self.bonded_accepted, self.comm)

    def restore_bonds(self, broken):
        """The bonds of a checkpoint (broken_bonds; collective)."""
        self.bonded_accepted = bonds_from_names(self.set, broken)
        self.set.bonded = self.bonded_accepted.copy()
        self._update_bonds(True)

    def _pose_on_full_system(self, separate_rows):
        """The VIProblem on the whole system: only the contact DOFs are bounded."""
        return VIProblem(self.comm, self.comm, self.prefix, None, self.prefix, self.A_vi, self.A.createVecRight(),
                         self.dofs, self.set.gap, self.set.sign, separate_rows=separate_rows)

    def method(self):
        if not self.schur:
            return "full"
        return f"condensed on {self.schur.size()} contact DOFs" + (", " + self.after if self.after else "")

    def reuses_factorization(self):
        """Whether the full path's Newton steps run GMRES on the last factorisation."""
        return not self.schur and self.vi.reuse

    def set_tolerance(self, relative):
        """Solves to `relative` (iterative full path): each Newton step's Krylov tolerance and Newton's (contact.h says why)."""
        self.vi.set_tolerance(relative)

    def preconditioner_setups(self):
        """Set-ups of the iterative full path's preconditioner (None otherwise)."""
        return self.vi.preconditioner_setups()

    def schur_columns(self):
        return self.schur.columns if self.schur else 0

    def schur_time(self):
        return self.schur.time if self.schur else 0.0

    def contact_factorizations(self):
        """The condensed VI's factorisations (0 on the full path: there they are the system's)."""
        return self.vi.factorizations()

    def operator_changed(self):
        """A was reassembled: H and A' are formed again at the next solve."""
        self.schur_current = self.change_current = False
        self.solved.forget()
        self.vi.operator_changed()

    def operator_nudged(self):
        """A few rows of A changed (a conduit's apertures): VariationalInequality.operator_nudged."""
        self.schur_current = self.change_current = False
        self.solved.forget()
        self.vi.operator_nudged()

    def solve(self, b, x):
        """Solves the VI; x holds the initial guess on entry. With friction, the slip
        increments are measured from the slip reference (friction.py)."""
        self._change_operators()
        b_vi, x_vi = b, self._to_vi(x)
        if self.change:
            self.change.dual(b, self.b_vi)
            b_vi = self.b_vi
        if not self.then_condensed or not self._solve_vi(b_vi, x_vi, self.full_steps):
            if self.then_condensed:
                self._switch_to_condensed("after one full Newton step" if self.full_steps == 1
                                          else "after two full Newton steps")
            # A solve that fails on every path is solved again from its start
            # (x_vi) when it broke a bond: the pairs that its clamped start
            # (every pair closed and stuck) pulls slip on friction alone
            # (contact_law.py). Bonds break only where no solution keeps them.
            rounds = 0
            while True:
                try:
                    self._solve_on_path(b_vi, x_vi)
                    break
                except SolverError as e:
                    # With friction, a change of load that changes too many states
                    # for one Newton solve: through the loads between (load_continuation.py).
                    if rounds == 0 and self.solved.known and continue_load(self.solved, b_vi, x_vi,
                                                                          self._solve_on_path, CONTINUATION_SOLVES):
                        break
                    if self._break_pulled_bonds():
                        rounds += 1
                        continue
                    if rounds == 0:
                        raise
                    raise BondFailure(f"{e} (also after breaking the bonds its clamped start pulled, {rounds} "
                                      f"{'time' if rounds == 1 else 'times'})") from None
        if self.vi.p.frictional:
            self.solved.keep(b_vi, x_vi)
        if self.change:
            self.change.backward(x_vi, x)

    def _solve_on_path(self, b_vi, x_vi):
        """Solves the VI for x' (in place) on the current path, and a failed
        full solve again condensed where the path's choice allows it: the
        condensed VI is the same problem with the other unknowns solved
        exactly at every Newton step, so its line search judges the contact
        rows alone and settles contact states between which the whole
        system's semismooth Newton steps cycle (docs/theory.md, "Friction").
        x_vi is still the start: a failed solve leaves it as it was."""
        if not self.condensed_on_failure:
            self._solve_vi(b_vi, x_vi, 0)
            return
        try:
            self._solve_vi(b_vi, x_vi, 0)
        except SolverError:
            full = self._switch_to_condensed("after a full solve that did not converge")
            try:
                self._solve_vi(b_vi, x_vi, 0)
            except SolverError:
                self._back_to_full(full)  # condensing did not mend it either: a broken bond may (solve)
                raise

    def _solve_vi(self, b_vi, x_vi, newton_steps):
        """Solves the VI for x' (in place) from the load b': at most
        `newton_steps` of one attempt (0: as many as it takes, raising
        SolverError if it fails); whether it converged."""
        if self.schur and not self.schur_current:
            self.schur.assemble()
            self.schur_current = True
        # The VI's load and start: on C alone when condensed, (H, g) with
        # y = x_C (schur_complement.py).
        load, y = self.vi.load(), self.vi.unknown()
        if self.schur:
            with load as g:
                g[:] = self.schur.condensed_load(b_vi)
            with y as Y:
                Y[:] = self.schur.restrict_to_contact(x_vi)
        else:
            b_vi.copy(load)
            x_vi.copy(y)
        self.vi.pin(self._pins_in_vi() if self.pinned else [])
        # in units of the displacement scale (the largest gap or |x|)
        scale = displacement_scale(self.set, self.displacement_dofs, x_vi, self.comm)
        if newton_steps == 0:
            self.vi.solve(scale)
        elif not self.vi.try_solve(scale, newton_steps):
            return False
        if self.schur:
            self.schur.extend(b_vi, y.getArray(readonly=True), x_vi)
        else:
            y.copy(x_vi)
        return True

    def set_slip_reference(self, x):
        """A time step (or window) starts at x: the slip increments
        (friction's, and those fault.xdmf writes) are measured from it
        (collective)."""
        x.copy(self.x_start)
        # A step tried again starts from the bonds of the last accepted one.
        changed = bool(np.any(self.set.bonded != self.bonded_accepted))
        self.set.bonded = self.bonded_accepted.copy()
        self._update_bonds(changed)
        reference = self.vi.slip_reference()
        if reference is None:
            return
        x_vi = self._to_vi(x)
        if self.schur:
            with reference as r:
                r[:] = self.schur.restrict_to_contact(x_vi)
        else:
            x_vi.copy(reference)

    def _make_change_of_variables(self):
        """The change of variables of the inclined and curved foundations,
        made when any node needs one (collective), and its operators."""
        self.A_vi, self.P_vi, self.change, self.change_current = self.A, self.P, None, True
        self.x_vi = self.b_vi = None
        if self.comm.allreduce(len(self.set.blocks), op=MPI.SUM) == 0:
            return
        requested = np.concatenate([dofs for dofs, _ in self.set.blocks] or [np.zeros(0, dtype=np.int64)])
        positions = iter(solved_positions(requested, self.A.getOwnershipRange()[0], self.displacement_dofs,
                                          self.set.dof_offset, self.comm))
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

    def _start_vi(self):
        """x' of the step's start (in its own work vector)."""
        if not self.change:
            return self.x_start
        self.change.forward(self.x_start, self.x_start_vi)
        return self.x_start_vi

    def distances(self, x):
        """The distance g - u.nu_F of each constraint at x."""
        return self.set.gap - self.set.sign * self._to_vi(x).getArray(readonly=True)[self.dofs]

    def active_set(self, x):
        """Constraints on the foundation to round-off: the active flag of
        state(), without the contact forces (collective)."""
        flags = on_foundation(self.distances(x), displacement_scale(self.set, self.displacement_dofs, x, self.comm))
        return ActiveSet(flags, self.comm.allreduce(int(np.sum(flags)), op=MPI.SUM))

    def _contact_force(self, x, b):
        """R' = T^{-T} (A x - b) at x, each constraint's multiplier."""
        self.A.mult(x, self.force)
        self.force.axpy(-1.0, b)
        if not self.change:
            return self.force
        self.change.dual(self.force, self.b_vi)
        return self.b_vi

    def state(self, x, b, pressure_out, active_out):
        """Contact diagnostics of x (collective); fills the output fields."""
        distance = self.distances(x)
        R = self._contact_force(x, b).getArray(readonly=True)
        pressure = contact_pressures(self.set, self.dofs, R)
        X = self._to_vi(x).getArray(readonly=True)
        jumps = [junction_jumps(self.set, self.displacement_dofs, v, self.comm) for v in (x, self.x_start)]
        measured = ContactMeasurement(self.set, self.displacement_dofs, distance, pressure,
                                      displacement_scale(self.set, self.displacement_dofs, x, self.comm), X, self._start_vi().getArray(readonly=True), R,
                                      *jumps)
        return contact_state(measured, ContactFields(pressure_out, active_out), self.comm)

    @property
    def newton_iterations(self):
        return self.vi.newton_iterations

    @property
    def linear_iterations(self):
        """Krylov iterations (1 per back-solve when direct)."""
        return self.vi.linear_iterations

    @property
    def active_set_changes(self):
        """Newton steps whose inactive set differed from the previous step's (across solves)."""
        return self.vi.convergence.active_set_changes

    def on_newton_step(self, told):
        """`told` is called after each Newton step with its number (the progress line)."""
        self.vi.convergence.on_newton_step = told
