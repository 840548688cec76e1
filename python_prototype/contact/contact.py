"""Frictionless Signorini contact against a rigid foundation with normal
nu_F = +-e_i (alg. "Mechanics with frictionless Signorini contact";
cpp/contact/contact.cpp), for the mechanics and the monolithic systems alike.

The energy is quadratic, so with A the system matrix and b its load vector
the variational inequality is the bound-constrained problem: find x with
l <= x <= g and F(x) = A x - b complementary to the bounds, bounds only on
the DOF of each contact node along nu_F (u.nu_F <= g_a). PETSc's
reduced-space active-set Newton (SNES vinewtonrsls) solves it.
"""
import numpy as np
from dolfinx import fem
from mpi4py import MPI
from petsc4py import PETSc

from ..assembly.linear_algebra import accumulate_ghosts, add_vector, owned, set_lag_preconditioner
from .schur_complement import SchurComplement
from ..solvers.inactive_set_preconditioner import InactiveSetPreconditioner
from ..solvers.solver import (ITERATIVE_TOLERANCE, LinearSolver, Method, OptionsError, SolverError, SolverStage, Structure,
                     reason_name, set_default_option, set_relative_tolerance, system_name)
from ..scene.scene import SceneError, agree_on_error


class ContactSet:
    """For each node of Gamma_3 owned here: its DOF along nu_F = sign e_axis,
    its gap g_a and its lumped boundary measure; `output_space` is the P1
    scalar space of that component, `output_dofs` the node's DOF there."""

    def __init__(self, scene, domain, F, V):
        fdim = domain.dim - 1
        contacts = [(name, b) for name, b in scene.boundaries.items() if b.contact]
        self.axis, self.sign = contacts[0][1].contact.axis, contacts[0][1].contact.sign
        for name, b in contacts[1:]:
            if (b.contact.axis, b.contact.sign) != (self.axis, self.sign):
                raise SceneError(f"{scene.file}: boundary.{name}.contact.normal: all contact boundaries "
                                 "must share one foundation normal")
        facets = np.unique(np.concatenate([domain.boundaries[name] for name, _ in contacts]))

        # Lumped boundary measure of each node: the integral of its hat function.
        lumped = fem.Function(V)
        add_vector(lumped, F.compile("L_lumped_boundary", domain.marker(facets=facets)))
        accumulate_ghosts(lumped)

        Vi = V.sub(self.axis)
        self.output_space, _ = Vi.collapse()
        coords = V.tabulate_dof_coordinates()
        bs, n_owned = V.dofmap.index_map_bs, owned(V)
        self.dofs, self.gap, self.lumped, self.output_dofs, seen = [], [], [], [], set()
        error = ""  # the first bad gap on this rank
        for name, b in contacts:
            dofs, collapsed = fem.locate_dofs_topological((Vi, self.output_space), fdim,
                                                          domain.boundaries[name])
            for dof, out in zip(dofs, collapsed):
                if dof >= n_owned or dof in seen:
                    continue
                seen.add(dof)
                x = coords[dof // bs]
                g = float(b.contact.gap(x[0], x[1], x[2], 0.0))
                if (not (g >= 0) or not np.isfinite(g)) and not error:
                    error = (f"{scene.file}: boundary.{name}.contact.gap: must be >= 0, got {g:f} "
                             f"at ({x[0]:f}, {x[1]:f})")
                self.dofs.append(dof)
                self.gap.append(g)
                self.lumped.append(lumped.x.array[dof])
                self.output_dofs.append(out)
        agree_on_error(error, domain.mesh.comm)
        self.dofs = np.array(self.dofs, dtype=np.int32)
        self.gap, self.lumped = np.array(self.gap), np.array(self.lumped)
        self.output_dofs = np.array(self.output_dofs, dtype=np.int32)


def contact_boundary_flag(contact_set):
    """The contact boundary as a P1 field for output: exactly 1 at the
    contact nodes, 0 elsewhere (cpp/contact/contact.h)."""
    flag = fem.Function(contact_set.output_space, name="contact_boundary")
    flag.x.array[contact_set.output_dofs] = 1.0
    flag.x.scatter_forward()
    return flag


def make_contact_fields(contact_set):
    """The output fields of a contact set: the contact pressure and active
    flag (zero off Gamma_3) and the contact_boundary_flag."""
    return (fem.Function(contact_set.output_space), fem.Function(contact_set.output_space),
            contact_boundary_flag(contact_set))


class ContactState:
    """Contact diagnostics after a solve (cpp/contact/contact.h)."""

    def __init__(self):
        self.active_nodes = self.contact_nodes = 0
        self.max_penetration = self.max_pressure = self.min_pressure = 0.0
        self.max_complementarity = self.gap_scale = self.total_force = 0.0


def use_condensation(prefix, method, contact_dofs):
    """-<prefix>contact_condensed, by default when the system is solved
    directly and C is small enough (cpp/contact/contact.cpp): forming H takes m
    solves, cheap back-solves of a factorisation but full Krylov solves."""
    options = PETSc.Options()
    if options.hasName(prefix + "contact_condensed"):
        return options.getBool(prefix + "contact_condensed")
    return method == Method.direct and contact_dofs <= ContactSolver.max_condensed_dofs


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

    def __init__(self, comm, prefix, A, P, fields, structure, method, contact_set, dofs, displacement_dofs):
        """On the iterative full path the Newton steps are preconditioned from
        P (A, or the fixed-stress matrix) split along `fields`."""
        self.comm, self.A, self.P, self.fields, self.set, self.prefix = comm, A, P, fields, contact_set, prefix
        self.structure = structure
        if structure == Structure.spd:  # carries over to the inactive-set submatrices
            A.setOption(PETSc.Mat.Option.SPD, True)
        self.dofs, self.displacement_dofs = np.asarray(dofs, dtype=np.int32), np.asarray(displacement_dofs)
        self.force = A.createVecRight()
        self.schur, self.schur_current, self.vi_stage, self.preconditioner = None, False, None, None
        vi_prefix = prefix
        condensed = use_condensation(prefix, method, comm.allreduce(len(self.dofs), op=MPI.SUM))
        if condensed:
            self.schur = SchurComplement(comm, prefix, A, structure, self.dofs)
            self.vi_stage = SolverStage(prefix + "contact")
            self.vi_comm, self.vi_mpi_comm, self.K = PETSc.COMM_SELF, MPI.COMM_SELF, self.schur.H
            self.bounded = np.arange(self.schur.size(), dtype=np.int32)
            self.bounded_gap = self.schur.gather(self.set.gap)
            self.x = PETSc.Vec().createSeq(self.schur.size(), comm=PETSc.COMM_SELF)
            # H is small and dense: LAPACK's factorisation, Cholesky when A is SPD.
            vi_prefix = prefix + "contact_"
            set_default_option(vi_prefix + "ksp_type", "preonly")
            set_default_option(vi_prefix + "pc_type", "cholesky" if structure == Structure.spd else "lu")
            set_default_option(vi_prefix + "pc_factor_mat_solver_type", "petsc")
        else:
            self.vi_comm, self.vi_mpi_comm, self.K = comm, comm, A
            self.bounded, self.bounded_gap = self.dofs, self.set.gap
            self.x = A.createVecRight()
        self.residual, self.lower, self.upper, self.b_scaled = (self.x.duplicate() for _ in range(4))
        self.lower.set(PETSc.NINFINITY)
        self.upper.set(PETSc.INFINITY)
        self.lag_by_default = not PETSc.Options().hasName(vi_prefix + "snes_lag_preconditioner")
        self.snes_rtol_given = PETSc.Options().hasName(vi_prefix + "snes_rtol")
        for option, value in (("snes_lag_preconditioner", "-2"), ("snes_rtol", "1e-10"),
                              ("snes_stol", "1e-12"), ("snes_max_it", "100"),
                              # F is linear, K exact: the full step is exact on the active set
                              ("snes_linesearch_type", "basic")):
            set_default_option(vi_prefix + option, value)
        self.snes = PETSc.SNES().create(self.vi_comm)
        self.snes.setOptionsPrefix(vi_prefix)
        self.snes.setType("vinewtonrsls")
        self.snes.setFunction(self._residual, self.residual)
        self.snes.setJacobian(lambda snes, x, J, P: None, self.K, self.K)
        self.snes.setVariableBounds(self.lower, self.upper)
        self.snes.setConvergenceTest(self._converged)
        if not condensed and method == Method.iterative:
            self.snes.getKSP().setMonitor(self._stagnation)
            self.preconditioner = InactiveSetPreconditioner(self.snes, P, fields, prefix)
            self.set_tolerance(ITERATIVE_TOLERANCE)
        # At least one Newton step per solve, so the result never lags the load.
        if hasattr(self.snes, "setForceIteration"):
            self.snes.setForceIteration(True)
        else:
            set_default_option(vi_prefix + "snes_force_iteration", "true")
        self.snes.setMonitor(self._monitor)
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
        self.pending = self.used = None  # active flags of the contact DOFs
        self.set_repeated, self.relative_target = False, 0.0
        self.residuals, self.lowered_from = [], 0  # of the current Krylov solve (stagnation)
        # Called after each Newton step with its number: a long solve's sign
        # of life (the run's progress line).
        self.on_newton_step = None

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
        self.schur_current = False
        if self.lag_by_default:
            set_lag_preconditioner(self.snes, -2)

    def _active_contact_dofs(self, x):
        """PETSc's rule (SNESVIGetActiveSetIS): on a bound to 1e-8, pushed against it."""
        X, F = x.getArray(readonly=True), self.snes.getFunction()[0].getArray(readonly=True)
        lo, up = self.lower.getArray(readonly=True), self.upper.getArray(readonly=True)
        i = self.bounded
        return ((X[i] <= lo[i] + 1e-8) & (F[i] > 0)) | ((X[i] >= up[i] - 1e-8) & (F[i] < 0))

    def _monitor(self, snes, iteration, norm):
        """Before each Newton step (and after the last): the set the next step uses."""
        if iteration > 0:
            changed = self.used is not None and not np.array_equal(self.pending, self.used)
            self.active_set_changes += int(self.vi_mpi_comm.allreduce(int(changed), op=MPI.MAX))
            self.used = self.pending
        self.pending = self._active_contact_dofs(snes.getSolution())
        if iteration > 0:
            differs = not np.array_equal(self.pending, self.used)
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
        lies above atol (cpp/contact/contact.cpp)."""
        _, _, fnorm = norms
        rtol, atol, _, _ = snes.getTolerances()
        if iteration == 0:
            self.relative_target = rtol * fnorm
        reasons = PETSc.SNES.ConvergedReason
        if not np.isfinite(fnorm):
            return reasons.DIVERGED_FNORM_NAN
        if iteration > 0 and fnorm < atol:
            return reasons.CONVERGED_FNORM_ABS
        if iteration > 0 and fnorm < self.relative_target:
            return reasons.CONVERGED_FNORM_RELATIVE
        if iteration > 0 and self.set_repeated:
            return reasons.CONVERGED_ITS
        return reasons.CONVERGED_ITERATING

    def _residual(self, snes, x, F):
        self.K.mult(x, F)
        F.axpy(-1.0, self.b_scaled)

    def displacement_scale(self, x):
        """The largest gap or |displacement| (collective)."""
        local = max(self.set.gap.max(initial=0.0),
                    np.abs(x.getArray(readonly=True)[self.displacement_dofs]).max(initial=0.0))
        s = self.comm.allreduce(local, op=MPI.MAX)
        return s if s > 0 else 1.0

    def solve(self, b, x):
        """Solves the VI; x holds the initial guess on entry."""
        if self.schur and not self.schur_current:
            self.schur.assemble()
            self.schur_current = True
        scale = self.displacement_scale(x)
        # u.nu_F <= g_a with nu_F = sign e_axis: u_axis <= g_a or u_axis >= -g_a.
        if self.set.sign > 0:
            with self.upper as up:
                up[self.bounded] = self.bounded_gap / scale
        else:
            with self.lower as lo:
                lo[self.bounded] = -self.bounded_gap / scale
        if self.schur:  # the VI on C alone: (H, g) with y = x_C
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
            # absolute tolerance relative to the load: scale-free
            self.snes.setTolerances(atol=max(1e-10 * self.b_scaled.norm(), 1e-300))
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
        self.x.scale(scale)
        if self.schur:
            self.schur.extend(b, self.x.getArray(readonly=True), x)
        else:
            self.x.copy(x)

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
        bound = (self.upper if self.set.sign > 0 else self.lower).getArray(readonly=True)
        with self.x as x:
            x[self.bounded] = bound[self.bounded]
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
        A = clamped_copy(self.A, rhs)
        P = A if self.P is self.A else clamped_copy(self.P)
        LinearSolver(self.comm, self.prefix, A, P, self.structure, self.fields).solve(self.x, rhs)

    def active_nodes(self, x):
        """Contact nodes on the foundation to round-off: the active flag of
        state(), without the contact forces (collective)."""
        scale = self.displacement_scale(x)
        distance = self.set.gap - self.set.sign * x.getArray(readonly=True)[self.dofs]
        return self.comm.allreduce(int(np.sum(distance <= 1e-9 * scale)), op=MPI.SUM)

    def state(self, x, b, pressure_out, active_out):
        """Contact force R = A x - b at the contact DOFs; contact pressure
        -R.nu_F / lumped measure; a node is active on the foundation to round-off."""
        s = ContactState()
        self.A.mult(x, self.force)
        self.force.axpy(-1.0, b)
        R, X = self.force.getArray(readonly=True), x.getArray(readonly=True)
        sign, gap = self.set.sign, self.set.gap
        normal = sign * X[self.dofs]
        pressure = -sign * R[self.dofs] / self.set.lumped
        s.gap_scale = self.displacement_scale(x)
        distance = gap - normal
        active = distance <= 1e-9 * s.gap_scale
        pressure_out.x.array[:] = 0.0
        active_out.x.array[:] = 0.0
        pressure_out.x.array[self.set.output_dofs] = pressure
        active_out.x.array[self.set.output_dofs] = active * 1.0
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
        return s
