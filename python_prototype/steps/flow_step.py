"""The flow step: one backward-Euler step of the mixed Darcy system with the
fixed-stress term (cpp/steps/flow_step.cpp)."""
import time

from dolfinx import fem

from ..solvers.field_split import Field
from ..assembly.parameters import interpolate, interpolate_resistivity
from ..assembly.linear_algebra import (accumulate_ghosts, add_vector, assemble_operator, dof_map, multiply_add, owned_global_dofs, reassemble_operator)
from ..solvers.solver import Structure
from ..solvers.system import System
from ..assembly.boundary_conditions import no_flow_bc


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
        # Quasi-definite when S + L > 0 (cpp/steps/flow_step.cpp): factorised once per dt.
        storage = float(F["storage"].value) + float(F["L"].value)
        self.system = System(comm, "flow_", self.a, self.bcs,
                             Structure.quasi_definite if storage > 0 else Structure.general,
                             scene.solver.flow, self.fields(W))
        self.b, self.b_loads = fem.Function(W), fem.Function(W)
        # The loads of the last `load_times` times, oldest first (cpp/steps/flow_step.h).
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

