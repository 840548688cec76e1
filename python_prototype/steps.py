"""The solves of one time step (cpp/linear_algebra.cpp, boundary_conditions.cpp,
flow_step.cpp, mechanics_step.cpp, contact.cpp, monolithic.cpp, diagnostics.cpp).

Every matrix is assembled and factorised once per run (it depends on dt and
L only), the loads once per time, the coupling terms once per iteration.
Right-hand sides are Functions used as vectors: `.x.array` holds owned and
ghost entries (assembly adds into both), `.vector` is the PETSc view.
"""
import time

import numpy as np
from dolfinx import fem, mesh as dmesh
from dolfinx.cpp.la import ScatterMode
from mpi4py import MPI
from petsc4py import PETSc

from .forms import interpolate, interpolate_resistivity
from .scene import SceneError


class SolverError(Exception):
    """A solver did not converge: the run stops with this message (exit 3)."""


def _reason_name(enum, reason):
    return next((k for k in dir(enum) if not k.startswith("_") and getattr(enum, k) == reason), str(reason))


# ---- linear algebra -------------------------------------------------------------

def set_default_option(name, value):
    """Sets a PETSc option unless the command line gave it."""
    options = PETSc.Options()
    if not options.hasName(name):
        options.setValue(name, value)


def assemble_matrix(a, bcs):
    """Rows and columns of Dirichlet DOFs become identity rows."""
    A = fem.petsc.assemble_matrix(a, bcs)
    A.assemble()
    return A


def add_vector(b, L):
    """Adds the local contributions of L to the Function-vector b (ghosts too)."""
    fem.assemble_vector(b.x.array, L)


def accumulate_ghosts(b):
    b.x.scatter_reverse(ScatterMode.add)


def finish_rhs(b, a, bcs):
    """Lifts the Dirichlet values of `a`, accumulates ghosts, sets the Dirichlet rows."""
    if bcs:
        fem.apply_lifting(b.x.array, [a], [bcs])
    accumulate_ghosts(b)
    if bcs:
        fem.set_bc(b.x.array, bcs)


def owned(V):
    """Number of owned (unrolled) DOFs of V on this rank."""
    return V.dofmap.index_map.size_local * V.dofmap.index_map_bs


def owned_norm(x, V, comm):
    """Euclidean norm of the owned part of a DOF array (collective)."""
    n = owned(V)
    return np.sqrt(comm.allreduce(float(np.dot(x[:n], x[:n])), op=MPI.SUM))


def dof_map(space, sub):
    """For every DOF of `space` (unrolled, ghosts too) its DOF in the parent
    of `sub`, a subspace with the same element (cpp collapse() maps)."""
    collapsed, to_parent = sub.collapse()
    bs = space.dofmap.index_map_bs
    im = space.dofmap.index_map
    node = np.empty(im.size_local + im.num_ghosts, dtype=np.int64)
    node[space.dofmap.list.array] = collapsed.dofmap.list.array
    unrolled = (bs * node[:, None] + np.arange(bs)).ravel()
    return np.asarray(to_parent)[unrolled]


class LinearSolver:
    """KSP with an options prefix; MUMPS LU unless -<prefix>ksp_type/pc_type
    say otherwise. The operator is factorised once and reused."""

    def __init__(self, comm, prefix, A):
        self.prefix = prefix
        set_default_option(prefix + "ksp_type", "preonly")
        set_default_option(prefix + "pc_type", "lu")
        set_default_option(prefix + "pc_factor_mat_solver_type", "mumps")
        self.ksp = PETSc.KSP().create(comm)
        self.ksp.setOptionsPrefix(prefix)
        self.ksp.setOperators(A, A)
        self.ksp.setFromOptions()

    def solve(self, x, b):
        try:
            self.ksp.solve(b, x)
        except PETSc.Error as e:  # e.g. a factorisation PETSc does not have for this matrix
            raise SolverError(f"the {self.prefix[:-1]} linear solver failed: PETSc error {e.ierr}") from None
        reason = self.ksp.getConvergedReason()
        if reason < 0:
            raise SolverError(f"the {self.prefix[:-1]} linear solver failed: "
                              f"{_reason_name(PETSc.KSP.ConvergedReason, reason)}")
        return self.ksp.getIterationNumber()


# ---- essential boundary conditions -------------------------------------------

def displacement_bcs(scene, domain, U):
    """One DirichletBC per prescribed displacement component; returns the
    conditions and (expression, value Function) pairs to update in time."""
    bcs, values = [], []
    d = domain.dim
    for name, b in scene.boundaries.items():
        for i in range(d):
            if b.displacement[i] is None:
                continue
            Ui = U.sub(i)
            collapsed, _ = Ui.collapse()
            g = fem.Function(collapsed)
            dofs = fem.locate_dofs_topological((Ui, collapsed), d - 1, domain.boundaries[name])
            bcs.append(fem.dirichletbc(g, dofs, Ui))
            values.append((b.displacement[i], g))
    return bcs, values


def update(values, t):
    for expression, g in values:
        interpolate(g, [expression], t)


def no_flow_bc(scene, domain, Z):
    """w.n = 0 on every boundary facet that is not a pressure boundary."""
    facets = dmesh.exterior_facet_indices(domain.mesh.topology)
    for name, b in scene.boundaries.items():
        if b.flow == "pressure":
            facets = np.setdiff1d(facets, domain.boundaries[name])
    collapsed, _ = Z.collapse()
    dofs = fem.locate_dofs_topological((Z, collapsed), domain.dim - 1, facets)
    return fem.dirichletbc(fem.Function(collapsed), dofs, Z)


# ---- flow (alg. "Flow"; fixed-stress terms of alg. (a)) ------------------------

class FlowStep:
    """Mixed RT0 x P0, backward Euler, with the coupling right-hand side
    (alg. "Multirate ... (a)"; q = 1 is the single-rate step). Its data are
    build()'s coefficients: p_previous (p^{n+1,m-1}), p_iterate (p^{n,m}),
    p_iterate_previous (p^{n,m-1}), u_iterate (u^n), u_window (u_K)."""

    def __init__(self, scene, domain, F, coupled):
        self.scene = scene
        flow, comm = scene.flow, domain.mesh.comm
        W = F["W"]
        self.Z, self.Z_to_W = W.sub(0).collapse()
        self.Q = F["Q"]
        self.Q_to_W = dof_map(self.Q, W.sub(1))
        interpolate_resistivity(F["resistivity"], flow, domain.dim)

        self.w = fem.Function(W)
        self.z = fem.Function(self.Z)
        self.pressure = F["p"]  # also the pressure load of the mechanics
        self.p_previous, self.p_iterate, self.p_iterate_previous = \
            F["p_previous"], F["p_iterate"], F["p_iterate_previous"]
        self.u_iterate, self.u_window = (F["u_iterate"], F["u_window"]) if coupled else (None, None)
        interpolate(self.pressure, [flow.initial_pressure], 0.0)
        self.source, self.p_boundary = F["source"], F["p_boundary"]

        self.L_pressure, self.loads_depend_on_time = [], False
        for name, b in scene.boundaries.items():
            if b.flow == "pressure":
                self.L_pressure.append((b.pressure, F.compile("L_flow_pressure", domain.marker(name))))
                self.loads_depend_on_time |= b.pressure.depends_on_time
        self.bcs = [no_flow_bc(scene, domain, W.sub(0))]

        self.a = F.compile("a_flow")
        self.L_storage = F.compile("L_flow_storage")
        self.L_coupling = F.compile("L_flow_coupling") if coupled else None
        self.L_source = F.compile("L_flow_source") if flow.source else None
        if flow.source:
            self.loads_depend_on_time |= flow.source.depends_on_time
        self.L_gravity = F.compile("L_flow_gravity") if flow.gravity else None

        self.solves, self.linear_iterations = 0, 0
        self.assembly_time = self.solve_time = 0.0
        start = time.perf_counter()
        self.A = assemble_matrix(self.a, self.bcs)
        self.assembly_time += time.perf_counter() - start
        self.solver = LinearSolver(comm, "flow_", self.A)
        self.b, self.b_loads = fem.Function(W), fem.Function(W)
        self.loads_time = None

    def assemble_loads(self, t):
        """Source, boundary pressure, gravity: once per time (once per run if
        they do not depend on t)."""
        if self.loads_time is not None and (not self.loads_depend_on_time or t == self.loads_time):
            return
        self.b_loads.x.array[:] = 0.0
        if self.L_source:
            interpolate(self.source, [self.scene.flow.source], t)
            add_vector(self.b_loads, self.L_source)
        if self.L_gravity:
            add_vector(self.b_loads, self.L_gravity)
        for expression, form in self.L_pressure:
            interpolate(self.p_boundary, [expression], t)
            add_vector(self.b_loads, form)
        self.loads_time = t

    def solve(self, t):
        """(z, p) at time t from the coupling data; leaves p in `pressure`."""
        start = time.perf_counter()
        self.assemble_loads(t)
        self.b.x.array[:] = self.b_loads.x.array
        add_vector(self.b, self.L_storage)
        if self.L_coupling:
            add_vector(self.b, self.L_coupling)
        accumulate_ghosts(self.b)  # the essential flux values are zero: no lifting
        fem.set_bc(self.b.x.array, self.bcs)
        self.assembly_time += time.perf_counter() - start

        start = time.perf_counter()
        self.linear_iterations += self.solver.solve(self.w.vector, self.b.vector)
        self.w.x.scatter_forward()
        self.solve_time += time.perf_counter() - start
        self.solves += 1
        self.set_state(self.w.x.array)

    def state(self):
        return self.w.x.array

    def set_state(self, w):
        """Restores a mixed solution (the multirate scheme keeps one per fine step)."""
        if w is not self.w.x.array:
            self.w.x.array[:] = w
        self.pressure.x.array[:] = w[self.Q_to_W]

    def flux(self, out):
        """Cell averages of z: the RT0 field is linear on a cell, its value at
        the midpoint (the DG0 interpolation point) is its average."""
        self.z.x.array[:] = self.w.x.array[self.Z_to_W]
        out.interpolate(self.z)


# ---- contact (alg. "Mechanics with frictionless Signorini contact") ------------

class ContactSet:
    """For each node of Gamma_3 owned here: its DOF along nu_F = sign e_axis,
    its gap g_a and its lumped boundary measure; `output_space` is the P1
    scalar space of that component, `output_dofs` the node's DOF there."""

    def __init__(self, scene, domain, F, V):
        fdim, comm = domain.dim - 1, domain.mesh.comm
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
        for name, b in contacts:
            dofs, collapsed = fem.locate_dofs_topological((Vi, self.output_space), fdim,
                                                          domain.boundaries[name])
            for dof, out in zip(dofs, collapsed):
                if dof >= n_owned or dof in seen:
                    continue
                seen.add(dof)
                x = coords[dof // bs]
                g = float(b.contact.gap(x[0], x[1], x[2], 0.0))
                if not (g >= 0) or not np.isfinite(g):
                    raise SceneError(f"{scene.file}: boundary.{name}.contact.gap: must be >= 0, got {g:f} "
                                     f"at ({x[0]:f}, {x[1]:f})")
                self.dofs.append(dof)
                self.gap.append(g)
                self.lumped.append(lumped.x.array[dof])
                self.output_dofs.append(out)
        self.dofs = np.array(self.dofs, dtype=np.int32)
        self.gap, self.lumped = np.array(self.gap), np.array(self.lumped)
        self.output_dofs = np.array(self.output_dofs, dtype=np.int32)


class ContactState:
    """Contact diagnostics after a solve (cpp/contact.h)."""

    def __init__(self):
        self.active_nodes = self.contact_nodes = 0
        self.max_penetration = self.max_pressure = self.min_pressure = 0.0
        self.max_complementarity = self.gap_scale = self.total_force = 0.0


class ContactSolver:
    """The VI as a bound-constrained problem: l <= x <= g with F(x) = A x - b
    complementary to the bounds, bounds only on the contact DOFs. The energy
    is quadratic: A is the exact (constant) Jacobian. SNESVI decides "on the
    bound" with an absolute tolerance (1e-8), so it solves for x/s with s the
    displacement scale (largest gap or |x|): F = A (x/s) - b/s."""

    def __init__(self, comm, prefix, A, contact_set, dofs, displacement_dofs):
        self.comm, self.A, self.set, self.prefix = comm, A, contact_set, prefix
        self.dofs, self.displacement_dofs = np.asarray(dofs, dtype=np.int32), np.asarray(displacement_dofs)
        self.x, self.residual, self.lower, self.upper, self.b_scaled = (A.createVecRight() for _ in range(5))
        self.lower.set(PETSc.NINFINITY)
        self.upper.set(PETSc.INFINITY)
        for option, value in (("ksp_type", "preonly"), ("pc_type", "lu"),
                              ("pc_factor_mat_solver_type", "mumps"), ("snes_rtol", "1e-10"),
                              ("snes_stol", "1e-12"), ("snes_max_it", "100"),
                              # F is linear, A exact: the full step is exact on the active set
                              ("snes_linesearch_type", "basic")):
            set_default_option(prefix + option, value)
        self.snes = PETSc.SNES().create(comm)
        self.snes.setOptionsPrefix(prefix)
        self.snes.setType("vinewtonrsls")
        self.snes.setFunction(self._residual, self.residual)
        self.snes.setJacobian(lambda snes, x, J, P: None, A, A)
        self.snes.setVariableBounds(self.lower, self.upper)
        # At least one Newton step per solve, so the result never lags the load.
        if hasattr(self.snes, "setForceIteration"):
            self.snes.setForceIteration(True)
        else:
            set_default_option(prefix + "snes_force_iteration", "true")
        self.snes.setFromOptions()
        self.newton_iterations = self.linear_iterations = 0

    def _residual(self, snes, x, F):
        self.A.mult(x, F)
        F.axpy(-1.0, self.b_scaled)

    def displacement_scale(self, x):
        """The largest gap or |displacement| (collective)."""
        local = max(self.set.gap.max(initial=0.0),
                    np.abs(x.getArray(readonly=True)[self.displacement_dofs]).max(initial=0.0))
        s = self.comm.allreduce(local, op=MPI.MAX)
        return s if s > 0 else 1.0

    def solve(self, b, x):
        """Solves the VI; x holds the initial guess on entry."""
        scale = self.displacement_scale(x)
        # u.nu_F <= g_a with nu_F = sign e_axis: u_axis <= g_a or u_axis >= -g_a.
        if self.set.sign > 0:
            with self.upper as up:
                up[self.dofs] = self.set.gap / scale
        else:
            with self.lower as lo:
                lo[self.dofs] = -self.set.gap / scale
        b.copy(self.b_scaled)
        self.b_scaled.scale(1.0 / scale)
        x.copy(self.x)
        self.x.scale(1.0 / scale)
        if not PETSc.Options().hasName(self.prefix + "snes_atol"):
            # absolute tolerance relative to the load: scale-free
            self.snes.setTolerances(atol=max(1e-10 * self.b_scaled.norm(), 1e-300))
        self._snes_solve()
        reason = self.snes.getConvergedReason()
        if reason < 0:
            # A body held in the normal direction by the foundation alone is
            # semi-coercive: from a start where no contact DOF pushes on its
            # bound the reduced system is singular. Start again with every
            # contact node on the foundation; the contact forces there say
            # which nodes to release.
            self.clamped_start()
            self._snes_solve()
            reason = self.snes.getConvergedReason()
        if reason < 0:
            raise SolverError("the contact solver (SNES vinewtonrsls) did not converge: "
                              + _reason_name(PETSc.SNES.ConvergedReason, reason))
        self.newton_iterations += self.snes.getIterationNumber()
        self.linear_iterations += self.snes.getLinearSolveIterations()
        self.x.scale(scale)
        self.x.copy(x)

    def _snes_solve(self):
        try:
            self.snes.solve(None, self.x)
        except PETSc.Error as e:
            raise SolverError(f"the contact solver (SNES vinewtonrsls) failed: PETSc error {e.ierr}") from None

    def clamped_start(self):
        """Sets x to the solution of A x = b/s with x = g_a/s on the contact
        DOFs (rows and columns eliminated, known values moved to the right)."""
        bound = (self.upper if self.set.sign > 0 else self.lower).getArray(readonly=True)
        with self.x as x:
            x[self.dofs] = bound[self.dofs]
        rows = (self.x.getOwnershipRange()[0] + self.dofs).astype(PETSc.IntType)
        A, rhs = self.A.duplicate(copy=True), self.b_scaled.copy()
        A.zeroRowsColumns(rows, 1.0, self.x, rhs)
        LinearSolver(self.comm, self.prefix, A).solve(self.x, rhs)

    def state(self, x, b, pressure_out, active_out):
        """Contact force R = A x - b at the contact DOFs; contact pressure
        -R.nu_F / lumped measure; a node is active on the foundation to round-off."""
        s = ContactState()
        self.A.mult(x, self.residual)
        self.residual.axpy(-1.0, b)
        R, X = self.residual.getArray(readonly=True), x.getArray(readonly=True)
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


# ---- mechanics (paper eq. 3.16, with contact when the scene has it) ------------

class MechanicsStep:
    """a(u, v) - (alpha p, div v) = loads, with p = build()'s "p" (the flow
    pressure); a linear solve, or the contact VI."""

    def __init__(self, scene, domain, F, coupled):
        self.scene, comm = scene, domain.mesh.comm
        self.V = V = F["V"]
        self.u = fem.Function(V)
        self.body_force, self.traction = F["body_force"], F["traction"]
        self.bcs, self.bc_values = displacement_bcs(scene, domain, V)
        self.L_traction, self.loads_depend_on_time = [], False
        for name, b in scene.boundaries.items():
            if b.mechanics == "traction":
                self.L_traction.append((b.traction, F.compile("L_traction", domain.marker(name))))
                self.loads_depend_on_time |= any(e.depends_on_time for e in b.traction)
        self.loads_depend_on_time |= any(e.depends_on_time for e, _ in self.bc_values)
        self.a = F.compile("a_elastic")
        self.L_pressure = F.compile("L_pressure_load") if coupled else None
        self.L_body = F.compile("L_body_force") if scene.mechanics.body_force else None
        if self.L_body:
            self.loads_depend_on_time |= any(e.depends_on_time for e in scene.mechanics.body_force)

        self.solves = self.linear_iterations = self.newton_iterations = 0
        self.assembly_time = self.solve_time = 0.0
        start = time.perf_counter()
        self.A = assemble_matrix(self.a, self.bcs)  # a(u, v) never changes: once
        self.assembly_time += time.perf_counter() - start
        self.b, self.b_loads = fem.Function(V), fem.Function(V)
        self.loads_time = None
        self.contact = self.contact_pressure = self.contact_active = None
        if not scene.has_contact():
            self.solver = LinearSolver(comm, "mechanics_", self.A)
            return
        # Contact: bounds on the normal DOF of every node of Gamma_3.
        contact_set = ContactSet(scene, domain, F, V)
        self.contact_pressure = fem.Function(contact_set.output_space)
        self.contact_active = fem.Function(contact_set.output_space)
        self.contact = ContactSolver(comm, "mechanics_", self.A, contact_set, contact_set.dofs,
                                     np.arange(owned(V)))

    def assemble_rhs(self, t):
        if self.loads_time is None or (self.loads_depend_on_time and t != self.loads_time):
            self.b_loads.x.array[:] = 0.0
            if self.L_body:
                interpolate(self.body_force, self.scene.mechanics.body_force, t)
                add_vector(self.b_loads, self.L_body)
            for traction, form in self.L_traction:
                interpolate(self.traction, traction, t)
                add_vector(self.b_loads, form)
            update(self.bc_values, t)
            self.loads_time = t
        self.b.x.array[:] = self.b_loads.x.array
        if self.L_pressure:  # the pressure load changes every iteration
            add_vector(self.b, self.L_pressure)
        finish_rhs(self.b, self.a, self.bcs)

    def solve(self, t):
        start = time.perf_counter()
        self.assemble_rhs(t)
        self.assembly_time += time.perf_counter() - start
        start = time.perf_counter()
        if self.contact is None:
            self.linear_iterations += self.solver.solve(self.u.vector, self.b.vector)
        else:
            self.contact.solve(self.b.vector, self.u.vector)
            self.newton_iterations = self.contact.newton_iterations
            self.linear_iterations = self.contact.linear_iterations
        self.u.x.scatter_forward()
        self.solve_time += time.perf_counter() - start
        self.solves += 1

    def contact_state(self):
        """Also fills the contact pressure and active-flag fields."""
        if self.contact is None:
            return ContactState()
        return self.contact.state(self.u.vector, self.b.vector, self.contact_pressure, self.contact_active)


# ---- monolithic (alg. "Monolithic reference") ------------------------------------

class MonolithicStep:
    """(u, z, p) together on P1^d x RT0 x P0, one VI per step."""

    def __init__(self, scene, domain, F):
        self.scene, comm = scene, domain.mesh.comm
        X = F["X"]
        self.V, self.Q = F["V"], F["Q"]
        self.V_to_X, self.Q_to_X = dof_map(self.V, X.sub(0)), dof_map(self.Q, X.sub(2))
        self.Z, self.Z_to_X = X.sub(1).collapse()
        self.x, self.z = fem.Function(X), fem.Function(self.Z)
        self.u, self.pressure = fem.Function(self.V), fem.Function(self.Q)
        self.u_old, self.p_old = F["u_window"], F["p_previous"]
        interpolate(self.pressure, [scene.flow.initial_pressure], 0.0)
        self.x.x.array[self.Q_to_X] = self.pressure.x.array  # the first guess of a contact solve
        interpolate_resistivity(F["resistivity"], scene.flow, domain.dim)
        self.body_force, self.traction = F["body_force"], F["traction"]
        self.source, self.p_boundary = F["source"], F["p_boundary"]

        self.bcs, self.bc_values = displacement_bcs(scene, domain, X.sub(0))
        self.bcs.append(no_flow_bc(scene, domain, X.sub(1)))
        self.loads_depend_on_time = any(e.depends_on_time for e, _ in self.bc_values)
        self.L_traction, self.L_pressure = [], []
        for name, b in scene.boundaries.items():
            if b.mechanics == "traction":
                self.L_traction.append((b.traction, F.compile("L_monolithic_traction", domain.marker(name))))
                self.loads_depend_on_time |= any(e.depends_on_time for e in b.traction)
            if b.flow == "pressure":
                self.L_pressure.append((b.pressure, F.compile("L_monolithic_pressure", domain.marker(name))))
                self.loads_depend_on_time |= b.pressure.depends_on_time
        self.a = F.compile("a_monolithic")
        self.L_history = F.compile("L_monolithic_history")
        self.L_body = F.compile("L_monolithic_body_force") if scene.mechanics.body_force else None
        if self.L_body:
            self.loads_depend_on_time |= any(e.depends_on_time for e in scene.mechanics.body_force)
        self.L_source = F.compile("L_monolithic_source") if scene.flow.source else None
        if self.L_source:
            self.loads_depend_on_time |= scene.flow.source.depends_on_time
        self.L_gravity = F.compile("L_monolithic_gravity") if scene.flow.gravity else None

        self.solves = self.linear_iterations = self.newton_iterations = 0
        self.assembly_time = self.solve_time = 0.0
        start = time.perf_counter()
        self.A = assemble_matrix(self.a, self.bcs)  # depends on dt only: once
        self.assembly_time += time.perf_counter() - start
        self.b, self.b_loads = fem.Function(X), fem.Function(X)
        self.loads_time = None
        self.contact = self.contact_pressure = self.contact_active = None
        if not scene.has_contact():
            self.solver = LinearSolver(comm, "monolithic_", self.A)
            return
        # Contact: the bounds sit on the contact DOFs of the displacement block.
        contact_set = ContactSet(scene, domain, F, self.V)
        dofs = self.V_to_X[contact_set.dofs]
        if np.any(dofs >= owned(X)):
            raise RuntimeError("monolithic contact: a contact DOF owned in V is not owned in the mixed space")
        self.contact_pressure = fem.Function(contact_set.output_space)
        self.contact_active = fem.Function(contact_set.output_space)
        self.contact = ContactSolver(comm, "monolithic_", self.A, contact_set, dofs,
                                     self.V_to_X[:owned(self.V)])

    def assemble_loads(self, t):
        if self.loads_time is not None and (not self.loads_depend_on_time or t == self.loads_time):
            return
        self.b_loads.x.array[:] = 0.0
        if self.L_body:
            interpolate(self.body_force, self.scene.mechanics.body_force, t)
            add_vector(self.b_loads, self.L_body)
        for traction, form in self.L_traction:
            interpolate(self.traction, traction, t)
            add_vector(self.b_loads, form)
        if self.L_source:
            interpolate(self.source, [self.scene.flow.source], t)
            add_vector(self.b_loads, self.L_source)
        for value, form in self.L_pressure:
            interpolate(self.p_boundary, [value], t)
            add_vector(self.b_loads, form)
        if self.L_gravity:
            add_vector(self.b_loads, self.L_gravity)
        update(self.bc_values, t)
        self.loads_time = t

    def solve(self, t):
        """One backward-Euler step to time t from the state in u and pressure."""
        start = time.perf_counter()
        self.u_old.x.array[:] = self.u.x.array
        self.p_old.x.array[:] = self.pressure.x.array
        self.assemble_loads(t)
        self.b.x.array[:] = self.b_loads.x.array
        add_vector(self.b, self.L_history)
        finish_rhs(self.b, self.a, self.bcs)
        self.assembly_time += time.perf_counter() - start
        start = time.perf_counter()
        if self.contact is not None:
            self.contact.solve(self.b.vector, self.x.vector)
            self.newton_iterations = self.contact.newton_iterations
            self.linear_iterations = self.contact.linear_iterations
        else:
            self.linear_iterations += self.solver.solve(self.x.vector, self.b.vector)
        self.x.x.scatter_forward()
        self.solve_time += time.perf_counter() - start
        self.solves += 1
        self.u.x.array[:] = self.x.x.array[self.V_to_X]
        self.pressure.x.array[:] = self.x.x.array[self.Q_to_X]

    def flux(self, out):
        self.z.x.array[:] = self.x.x.array[self.Z_to_X]
        out.interpolate(self.z)

    def contact_state(self):
        if self.contact is None:
            return ContactState()
        return self.contact.state(self.x.vector, self.b.vector, self.contact_pressure, self.contact_active)


# ---- diagnostics (cpp/diagnostics.cpp) -------------------------------------------

class ContractionNorm:
    """||c_u div(du) - c_p dp||_L2 with the form M_contraction."""

    def __init__(self, F, comm):
        self.F, self.comm = F, comm
        self.M = F.compile("M_contraction")

    def __call__(self, c_u, du, c_p, dp):
        F = self.F
        F["du"].x.array[:] = du
        F["dp"].x.array[:] = dp
        F["c_u"].value, F["c_p"].value = c_u, c_p
        return np.sqrt(max(0.0, self.comm.allreduce(fem.assemble_scalar(self.M), op=MPI.SUM)))


def volumetric_stress(F, L_sigma_v, u, p, sigma_v):
    """sigma_v = lambda div u - alpha p in each cell (L_sigma_v); sigma_v on F["Q"]."""
    F["u_out"].x.array[:] = u.x.array
    F["p_out"].x.array[:] = p.x.array if p is not None else 0.0
    sigma_v.x.array[:] = 0.0
    add_vector(sigma_v, L_sigma_v)
    accumulate_ghosts(sigma_v)
    sigma_v.x.scatter_forward()


def relative_error(F, error, norm, comm):
    """||f - reference|| / ||reference|| with compiled forms (P2 reference)."""
    e = comm.allreduce(fem.assemble_scalar(error), op=MPI.SUM)
    n = comm.allreduce(fem.assemble_scalar(norm), op=MPI.SUM)
    return np.sqrt(e / n)
