"""The solves of one time step (cpp/boundary_conditions.cpp, flow_step.cpp,
mechanics_step.cpp, monolithic.cpp, diagnostics.cpp).

Every matrix is assembled once per run (it depends on dt and L only) and
solved by its System (system.py), the loads once per time, the coupling
terms once per iteration.
"""
import time

import numpy as np
from dolfinx import fem, mesh as dmesh
from mpi4py import MPI
from petsc4py import PETSc

from .contact import ContactSet, ContactState, contact_boundary_flag
from .field_split import Field, part_of
from .forms import interpolate, interpolate_resistivity
from .linear_algebra import (accumulate_ghosts, add_vector, assemble_operator, dof_map, finish_rhs, multiply_add,
                             owned, owned_global_dofs, reassemble_operator, rigid_body_modes)
from .solver import Method, Structure
from .system import System


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
            points = collapsed.tabulate_dof_coordinates()[dofs[1]]
            values.append((b.displacement[i], g, dofs[1], points))
    return bcs, values


def update(values, t):
    """The prescribed values at time t, evaluated at the boundary DOFs only
    (a closed form such as Mandel's plate displacement costs a series per point)."""
    for expression, g, dofs, points in values:
        g.x.array[dofs] = expression.at(points.T, t)


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
    (alg. "Multirate ... (a)"; q = 1 is the single-rate step) from the
    coupling data p_previous (p^{n+1,m-1}), p_iterate (p^{n,m}),
    p_iterate_previous (p^{n,m-1}), u_iterate (u^n), u_window (u_K), applied
    as operators (forms/biot.py) assembled once per dt."""

    def __init__(self, scene, domain, F, coupled):
        """With L = 0 in F (the second pass of "multirate-two-pass") the step
        has no stabilisation term."""
        self.scene, self.F = scene, F
        flow, comm = scene.flow, domain.mesh.comm
        W = F["W"]
        self.Z, self.Z_to_W = W.sub(0).collapse()
        self.Q = F["Q"]
        self.Q_to_W = dof_map(self.Q, W.sub(1))
        interpolate_resistivity(F["resistivity"], flow, domain.dim)

        self.w = fem.Function(W)
        self.z = fem.Function(self.Z)
        self.pressure = fem.Function(self.Q)  # also the pressure load of the mechanics
        self.p_previous, self.p_iterate, self.p_iterate_previous, self.dp = \
            (fem.Function(self.Q) for _ in range(4))
        self.u_iterate, self.u_window, self.du = (fem.Function(F["V"]) for _ in range(3)) if coupled \
            else (None, None, None)
        interpolate(self.pressure, [flow.initial_pressure], 0.0)
        self.source, self.p_boundary = F["source"], F["p_boundary"]

        self.L_pressure, self.loads_depend_on_time = [], False
        for name, b in scene.boundaries.items():
            if b.flow == "pressure":
                self.L_pressure.append((b.pressure, F.compile("L_flow_pressure", domain.marker(name))))
                self.loads_depend_on_time |= b.pressure.depends_on_time
        self.bcs = [no_flow_bc(scene, domain, W.sub(0))]

        self.a = F.compile("a_flow")
        # The terms that change every coupling iteration, as operators on the
        # iterates (W x Q, W x Q, W x V), assembled once per dt.
        operands = [("a_flow_storage", self.p_previous)]
        if coupled and float(F["L"].value) > 0:
            operands.append(("a_flow_stabilisation", self.dp))
        if coupled:
            operands.append(("a_flow_displacement", self.du))
        self.operators = []  # (form, matrix, operand)
        for name, x in operands:
            a = F.compile(name)
            self.operators.append((a, assemble_operator(a, self.bcs), x))
        self.L_source = F.compile("L_flow_source") if flow.source else None
        if flow.source:
            self.loads_depend_on_time |= flow.source.depends_on_time
        self.L_gravity = F.compile("L_flow_gravity") if flow.gravity else None

        self.assembly_time = 0.0  # right-hand sides
        # Quasi-definite when S + L > 0 (cpp/flow_step.cpp): factorised once per dt.
        storage = float(F["storage"].value) + float(F["L"].value)
        self.system = System(comm, "flow_", self.a, self.bcs,
                             Structure.quasi_definite if storage > 0 else Structure.general,
                             scene.solver.flow, self.fields(W))
        self.b, self.b_loads = fem.Function(W), fem.Function(W)
        # The loads of the last `load_times` times, oldest first (cpp/flow_step.h).
        self.loads_by_time, self.load_times = [], 1

    def keep_loads(self, times):
        """Keeps the loads of the last `times` solve times (q for a multirate
        window, whose iterations revisit its fine times)."""
        self.load_times = max(times, 1)

    def fields(self, W):
        """The flux and pressure DOFs of W (owned, global numbering): the
        splits of an iterative solve."""
        index_map = W.dofmap.index_map  # block size 1
        return [Field("flux", owned_global_dofs(index_map, self.Z_to_W)),
                Field("pressure", owned_global_dofs(index_map, self.Q_to_W))]

    def loads(self, t):
        """Source, boundary pressure, gravity at time t: assembled once per
        time (once per run if they do not depend on t), kept for the last
        keep_loads() times."""
        for time_, b in self.loads_by_time:
            if time_ == t or not self.loads_depend_on_time:
                return b
        if len(self.loads_by_time) >= self.load_times:
            self.loads_by_time.pop(0)
        self.b_loads.x.array[:] = 0.0
        if self.L_source:
            interpolate(self.source, [self.scene.flow.source], t)
            add_vector(self.b_loads, self.L_source)
        if self.L_gravity:
            add_vector(self.b_loads, self.L_gravity)
        for expression, form in self.L_pressure:
            interpolate(self.p_boundary, [expression], t)
            add_vector(self.b_loads, form)
        accumulate_ghosts(self.b_loads)  # the essential flux values are zero: no lifting
        fem.set_bc(self.b_loads.x.array, self.bcs)
        self.loads_by_time.append((t, self.b_loads.x.array.copy()))
        return self.loads_by_time[-1][1]

    def solve(self, t):
        """(z, p) at time t from the coupling data; leaves p in `pressure`:
        b = loads - ((S+L)/dt) p^{n+1,m-1} - (L/dt)(p^{n,m} - p^{n,m-1})
              + (alpha/(q dt)) div(u^n - u_K), tested with th."""
        start = time.perf_counter()
        self.b.x.array[:] = self.loads(t)
        if self.u_iterate is not None:
            self.dp.x.array[:] = self.p_iterate.x.array - self.p_iterate_previous.x.array
            self.du.x.array[:] = self.u_iterate.x.array - self.u_window.x.array
        for _, A, x in self.operators:
            multiply_add(A, x, self.b)
        self.assembly_time += time.perf_counter() - start

        self.system.solve(self.b.vector, self.w.vector)
        self.w.x.scatter_forward()
        self.set_state(self.w.x.array)

    def state(self):
        return self.w.x.array

    def time_step_changed(self):
        """The matrix and the operators depend on dt: reassembled after
        set_time_step changed it."""
        self.system.reassemble()
        start = time.perf_counter()
        for a, A, _ in self.operators:
            reassemble_operator(A, a, self.bcs)
        self.assembly_time += time.perf_counter() - start

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

# ---- mechanics (paper eq. 3.16, with contact when the scene has it) ------------

class MechanicsStep:
    """a(u, v) - (alpha p, div v) = loads, with p the flow pressure (None
    without flow); a linear solve, or the contact VI."""

    def __init__(self, scene, domain, F, pressure):
        self.scene, comm = scene, domain.mesh.comm
        self.V = V = F["V"]
        self.u = fem.Function(V)
        self.body_force, self.traction = F["body_force"], F["traction"]
        self.bcs, self.bc_values = displacement_bcs(scene, domain, V)
        self.L_traction, self.loads_depend_on_time = [], False
        for name, b in scene.boundaries.items():
            if b.traction:  # a traction boundary, or a loaded contact boundary
                self.L_traction.append((b.traction, F.compile("L_traction", domain.marker(name))))
                self.loads_depend_on_time |= any(e.depends_on_time for e in b.traction)
        self.loads_depend_on_time |= any(e.depends_on_time for e, *_ in self.bc_values)
        self.a = F.compile("a_elastic")
        # The pressure load (alpha p, div v), applied as an operator on p.
        self.pressure = pressure
        self.pressure_load = assemble_operator(F.compile("a_pressure_load"), self.bcs) \
            if pressure is not None else None
        self.L_body = F.compile("L_body_force") if scene.mechanics.body_force else None
        if self.L_body:
            self.loads_depend_on_time |= any(e.depends_on_time for e in scene.mechanics.body_force)

        self.assembly_time = 0.0  # right-hand sides
        # a(u, v) never changes: assembled once; SPD with identity Dirichlet rows.
        self.system = System(comm, "mechanics_", self.a, self.bcs, Structure.spd, scene.solver.mechanics)
        if self.system.method == Method.iterative:
            self.system.set_near_nullspace(rigid_body_modes(V))
        self.b, self.b_loads = fem.Function(V), fem.Function(V)
        self.loads_time = None
        self.contact_pressure = self.contact_active = self.contact_boundary = None
        if not scene.has_contact():
            return
        # Contact: bounds on the normal DOF of every node of Gamma_3.
        contact_set = ContactSet(scene, domain, F, V)
        self.contact_pressure = fem.Function(contact_set.output_space)
        self.contact_active = fem.Function(contact_set.output_space)
        self.contact_boundary = contact_boundary_flag(contact_set)
        self.system.use_contact(contact_set, contact_set.dofs, np.arange(owned(V)))

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
            finish_rhs(self.b_loads, self.a, self.bcs)  # lifted, Dirichlet values set: once per time
            self.loads_time = t
        self.b.x.array[:] = self.b_loads.x.array
        if self.pressure_load:  # changes every iteration; its Dirichlet rows are zero
            multiply_add(self.pressure_load, self.pressure, self.b)

    def solve(self, t):
        start = time.perf_counter()
        self.assemble_rhs(t)
        self.assembly_time += time.perf_counter() - start
        self.system.solve(self.b.vector, self.u.vector)
        self.u.x.scatter_forward()

    def active_contact_nodes(self):
        """Only the number of active contact nodes of u, for the log of every iteration."""
        return self.system.contact.active_nodes(self.u.vector) if self.system.has_contact() else 0

    def contact_state(self):
        """Also fills the contact pressure and active-flag fields."""
        if not self.system.has_contact():
            return ContactState()
        return self.system.contact.state(self.u.vector, self.b.vector, self.contact_pressure,
                                         self.contact_active)


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
        self.loads_depend_on_time = any(e.depends_on_time for e, *_ in self.bc_values)
        self.L_traction, self.L_pressure = [], []
        for name, b in scene.boundaries.items():
            if b.traction:  # a traction boundary, or a loaded contact boundary
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

        self.assembly_time = 0.0  # right-hand sides
        # Depends on dt only; its pressure block -(S/dt) is often negligible
        # against the coupling: LU with pivoting (cpp/monolithic.cpp). The
        # iterative path is preconditioned by the fixed-stress split.
        self.system = System(comm, "monolithic_", self.a, self.bcs, Structure.general, scene.solver.monolithic,
                             self.fields(X), F.compile("a_monolithic_preconditioner"))
        self.b, self.b_loads = fem.Function(X), fem.Function(X)
        self.loads_time = None
        self.contact_pressure = self.contact_active = self.contact_boundary = None
        if not scene.has_contact():
            return
        # Contact: the bounds sit on the contact DOFs of the displacement block.
        contact_set = ContactSet(scene, domain, F, self.V)
        dofs = self.V_to_X[contact_set.dofs]
        if np.any(dofs >= owned(X)):
            raise RuntimeError("monolithic contact: a contact DOF owned in V is not owned in the mixed space")
        self.contact_pressure = fem.Function(contact_set.output_space)
        self.contact_active = fem.Function(contact_set.output_space)
        self.contact_boundary = contact_boundary_flag(contact_set)
        self.system.use_contact(contact_set, dofs, self.V_to_X[:owned(self.V)])

    def fields(self, X):
        """The splits of (u, z, p) for the fixed-stress preconditioner: the
        flow (flux, pressure), then the mechanics node by node with the
        rigid-body modes in its numbering (cpp/monolithic.cpp)."""
        comm, index_map = X.mesh.comm, X.dofmap.index_map  # block size 1
        z, p = owned_global_dofs(index_map, self.Z_to_X), owned_global_dofs(index_map, self.Q_to_X)
        u = owned_global_dofs(index_map, self.V_to_X)
        flow = Field("flow", np.sort(np.concatenate([z, p])))
        flow.fields = [part_of(flow, "flux", z, comm), part_of(flow, "pressure", p, comm)]
        position = np.searchsorted(u, index_map.local_range[0] + self.V_to_X[:owned(self.V)])
        mechanics = Field("mechanics", u, self.V.dofmap.index_map_bs, rigid_body_modes(self.V, position))
        return [flow, mechanics]

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

    def assemble_rhs(self, t):
        """The right-hand side of a step to t from the state in u and pressure."""
        start = time.perf_counter()
        self.u_old.x.array[:] = self.u.x.array
        self.p_old.x.array[:] = self.pressure.x.array
        self.assemble_loads(t)
        self.b.x.array[:] = self.b_loads.x.array
        add_vector(self.b, self.L_history)
        finish_rhs(self.b, self.a, self.bcs)
        self.assembly_time += time.perf_counter() - start

    def set_displacement(self, u, t):
        """Sets the displacement of the state at time t (with the pressure now
        in `pressure`): the initial equilibrium (mechanics.initial_equilibrium);
        contact_state() then reads this state's residual."""
        self.u.x.array[:] = u
        self.x.x.array[self.V_to_X] = u
        self.x.x.array[self.Q_to_X] = self.pressure.x.array
        self.assemble_rhs(t)

    def solve(self, t):
        """One backward-Euler step to time t from the state in u and pressure."""
        self.assemble_rhs(t)
        self.system.solve(self.b.vector, self.x.vector)
        self.x.x.scatter_forward()
        self.u.x.array[:] = self.x.x.array[self.V_to_X]
        self.pressure.x.array[:] = self.x.x.array[self.Q_to_X]

    def time_step_changed(self):
        """The matrix depends on dt: reassembled after set_time_step changed it."""
        self.system.reassemble()

    def flux(self, out):
        self.z.x.array[:] = self.x.x.array[self.Z_to_X]
        out.interpolate(self.z)

    def state(self):
        """The coupled unknown (u, z, p), ghosts included, for a checkpoint."""
        return self.x.x.array

    def set_state(self, x):
        """Loads a state() back (and u, pressure from it)."""
        self.x.x.array[:] = x
        self.u.x.array[:] = self.x.x.array[self.V_to_X]
        self.pressure.x.array[:] = self.x.x.array[self.Q_to_X]

    def contact_state(self):
        if not self.system.has_contact():
            return ContactState()
        return self.system.contact.state(self.x.vector, self.b.vector, self.contact_pressure,
                                         self.contact_active)


# ---- diagnostics (cpp/diagnostics.cpp) -------------------------------------------

class ContractionNorm:
    """||c_u div(du) - c_p dp||_L2 (cpp/diagnostics.h): with D the operator of
    the cell integrals of div and |T| the cell volumes, for P1 du and P0 dp
    exactly sum_T (c_u (D du)_T - c_p |T| dp_T)^2 / |T|."""

    def __init__(self, F, comm):
        self.comm = comm
        self.D = assemble_operator(F.compile("a_divergence"), [])
        self.volume = fem.Function(F["Q"])
        add_vector(self.volume, F.compile("L_cell_volume"))
        accumulate_ghosts(self.volume)
        self.du, self.div_du = fem.Function(F["V"]), fem.Function(F["Q"])
        self.cells = F["Q"].dofmap.index_map.size_local

    def __call__(self, c_u, du, c_p, dp):
        self.du.x.array[:] = du
        self.D.mult(self.du.vector, self.div_du.vector)
        n = self.cells
        volume = self.volume.x.array[:n]
        w = c_u * self.div_du.x.array[:n] - c_p * volume * dp[:n]
        return np.sqrt(self.comm.allreduce(float(np.sum(w * w / volume)), op=MPI.SUM))


def volumetric_stress(F, L_sigma_v, u, p, sigma_v):
    """sigma_v = lambda div u - alpha p in each cell (L_sigma_v); sigma_v on F["Q"]."""
    F["u_out"].x.array[:] = u.x.array
    F["p_out"].x.array[:] = p.x.array if p is not None else 0.0
    sigma_v.x.array[:] = 0.0
    add_vector(sigma_v, L_sigma_v)
    accumulate_ghosts(sigma_v)
    sigma_v.x.scatter_forward()


def relative_error(F, error, norm, comm):
    """||f - reference|| / ||reference|| with compiled forms (P2 reference);
    NaN or inf, as in C++, when the reference is zero."""
    e = comm.allreduce(fem.assemble_scalar(error), op=MPI.SUM)
    n = comm.allreduce(fem.assemble_scalar(norm), op=MPI.SUM)
    with np.errstate(divide="ignore", invalid="ignore"):
        return float(np.sqrt(np.float64(e) / n))
