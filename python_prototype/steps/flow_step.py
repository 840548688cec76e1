"""The flow step: one backward-Euler step of the mixed Darcy system with the
fixed-stress term (cpp/steps/flow_step.cpp)."""
import enum
import time

import numpy as np
from dolfinx import fem

from ..solvers.field_split import Field
from ..scene.input import FaultFlow, TimeScheme
from ..assembly.loads import Loads
from ..assembly.parameters import interpolate
from ..assembly.linear_algebra import (accumulate_ghosts, assemble_operator, dof_map, finish_rhs, largest_entry,
                                       multiply_add, owned, owned_global_dofs, reassemble_operator, UnknownsPart)
from ..solvers.solver import Structure, SystemLayout
from .solve_record import FieldValues, SolveFields
from .step import Step, StepState
from .system import System
from ..assembly.boundary_conditions import facet_flux, fault_flux_ties, flux_bc, update_fluxes
from ..assembly.fault_aperture import FaultAperture
from ..assembly.fault_flow import ConduitFaults, FineStep
from .system import AppendedUnknowns
from ..assembly.wells import add_wells, depends_on_time, well_sources
from ..time.time_scheme import TimeDerivative, history_value


class FlowPass(enum.Enum):
    """The flow step's place in a scheme: the flow of every scheme, or the
    second pass of "multirate-two-pass" (L = 0 in its problem's materials:
    no stabilisation term; its time history is set by the split)."""
    first = 1
    second = 2


class FlowStep(Step):
    """Mixed RT0 x P0, backward Euler, with the coupling right-hand side
    (alg. "Multirate ... (a)"; q = 1 is the single-rate step) from the
    coupling data p_previous (p^{n+1,m-1}), p_iterate (p^{n,m}),
    p_iterate_previous (p^{n,m-1}), u_iterate (u^n), u_window (u_K), applied
    as operators (forms/biot.py) assembled once per dt."""

    def __init__(self, problem, V, flow_pass=FlowPass.first):
        """`V` is the displacement space of a coupled scene, None otherwise."""
        super().__init__()
        scene, domain, F, materials = problem.scene, problem.domain, problem.forms, problem.materials
        self.scene, self.F, self.flow_pass = scene, F, flow_pass
        flow, comm = scene.flow, domain.mesh.comm
        coupled = V is not None
        W = F["W"]
        self.Z, self.Z_to_W = W.sub(0).collapse()
        self.Q = F["Q"]
        self.Q_to_W = dof_map(self.Q, W.sub(1))

        self.w = fem.Function(W)
        self.z = fem.Function(self.Z)
        self.pressure = fem.Function(self.Q)  # also the pressure load of the mechanics
        self.p_previous, self.p_iterate, self.p_iterate_previous, self.dp = \
            (fem.Function(self.Q) for _ in range(4))
        self.u_iterate, self.u_window, self.du = (fem.Function(V) for _ in range(3)) if coupled \
            else (None, None, None)
        # The accumulation's memory for time.scheme = "bdf2" (time_scheme.py):
        # the pressure one fine step and the displacement one window before
        # the window's start, and the multirate displacement path's value one
        # fine step before it (u_* None without mechanics); checkpointed.
        self.p_before = fem.Function(self.Q)
        self.u_before, self.u_path_before = (fem.Function(V), fem.Function(V)) if coupled else (None, None)
        interpolate(self.pressure, [flow.initial_pressure], 0.0)

        # The normal flux (essential for RT) wherever no pressure is given:
        # zero (no flow) but on flux and rate boundaries.
        bc, self.fluxes = flux_bc(scene, domain, W.sub(0))
        self.bcs = [bc]
        self.make_loads(domain)

        self.a = F.compile("a_flow")
        # The terms that change every coupling iteration, as operators on the
        # iterates (W x Q, W x Q, W x V), assembled once per dt.
        operands = [("a_flow_storage", self.p_previous)]
        if coupled and materials.max_L > 0:
            operands.append(("a_flow_stabilisation", self.dp))
        if coupled:
            operands.append(("a_flow_displacement", self.du))
        self.operators = []  # (form, matrix, operand)
        for name, x in operands:
            a = F.compile(name)
            self.operators.append((a, assemble_operator(a, self.bcs), x))

        self.assembly_time = 0.0  # right-hand sides
        # Quasi-definite when S + L > 0 in every cell (cpp/steps/flow_step.cpp): factorised once per dt.
        structure = Structure.quasi_definite if materials.min_stabilised_storage > 0 else Structure.general
        self.system = System(comm, self.a, self.bcs, SystemLayout("flow_", structure, self.fields(W)),
                             scene.solver.flow)
        face_flux = facet_flux(F, "L_flow_pressure", "W")
        self.system.tie(fault_flux_ties(scene, domain, W.sub(0), face_flux))
        self.b = fem.Function(W)
        self.make_conduits(domain, face_flux, V)

    def make_conduits(self, domain, flux, V):
        """The conduit faults' pressure p_f (assembly/fault_flow.py), appended
        to the system, starting from the initial pressure at the cells'
        centroids (nothing without conduit faults); in a coupled scene
        their openings as a map of the displacement and the load of p_f on
        their faces (fault_aperture: the mechanics takes it)."""
        self.conduits = ConduitFaults(self.scene, domain, self.F["W"].sub(0), flux)
        if self.flow_pass == FlowPass.second:
            self.conduits.without_stabilisation()
        self.fault_pressure = np.zeros(self.conduits.owned)
        self.fault_pressure_previous = np.zeros(self.conduits.owned)
        self.fault_aperture = None
        self.traction_source = None  # the step whose fault_traction is s_n per conduit cell (read_fault_traction)
        self.fine_step = 1  # of the window (set_fine_step)
        self.derivative = TimeDerivative()  # of the step (advance, set_time_derivative)
        if not self.conduits:
            return
        self.fault_pressure[:] = self.conduits.initial_pressure(self.scene.flow.initial_pressure)
        if V is not None:
            self.fault_aperture = FaultAperture(self.scene, domain, V)
        self.append_conduits()

    def read_fault_traction(self, holder):
        """The conduit cells' effective normal stress s_n at the last
        mechanics solve (MechanicsStep.fault_traction, read from `holder`
        when needed), which their closure follows."""
        self.traction_source = holder

    def take_start_apertures(self, first):
        """The conduit faults' hydraulic apertures at the window's start are
        `first`'s (the second pass of "multirate-two-pass", which accepts no
        step of its own)."""
        self.conduits.set_start_apertures(first.conduits.start_apertures())

    def update_apertures(self):
        """The conduits' hydraulic apertures from the displacement now (u_K)
        and the normal stress of their closure, their rows appended again if
        they changed."""
        a = self.fault_aperture
        traction = self.traction_source.fault_traction if self.traction_source is not None else None
        if self.conduits.set_openings(a.opening(self.u_iterate), traction):
            self.append_conduits()

    def append_conduits(self):
        """The conduit faults' rows at the current dt, into the system."""
        dt = float(self.F["dt"].value)
        rows = self.F["W"].dofmap.index_map.size_local  # block size 1
        self.system.append(AppendedUnknowns(self.conduits.exchange(rows),
                                            self.conduits.operator_matrix(dt), self.conduits.face_resistance(),
                                            np.zeros(self.conduits.owned), self.fault_pressure))

    def make_loads(self, domain):
        """Source, gravity and boundary pressures (alg. "Flow"; a fault held at
        its pressure is a boundary pressure on its faces), in that order, then
        the wells, with the prescribed normal fluxes set; a non-zero one is lifted, its
        column moved to the right-hand side."""
        F, flow = self.F, self.scene.flow

        def finish(b, t):
            add_wells(self.wells, t, b.x.array)
            update_fluxes(self.fluxes, t)
            if self.fluxes.boundaries:
                return finish_rhs(b, self.a, self.bcs)
            accumulate_ghosts(b)
            fem.set_bc(b.x.array, self.bcs)
        self.loads = Loads(F["W"], finish)
        for f in self.fluxes.boundaries:
            self.loads.depends_on_time((f.rate or f.flux).depends_on_time)
        self.wells = well_sources(self.scene, domain, self.Q, self.Q_to_W)
        self.loads.depends_on_time(depends_on_time(self.wells))
        if flow.source:
            self.loads.add(F.compile("L_flow_source"), F["source"], [flow.source])
        if flow.gravity:
            self.loads.add(F.compile("L_flow_gravity"))
        for name, b in self.scene.boundaries.items():
            if b.flow == "pressure":
                self.loads.add_boundary(domain, name, lambda marker: F.compile("L_flow_pressure", marker),
                                        F["p_boundary"], [b.pressure])
        for name, f in self.scene.faults.items():
            if f.flow == FaultFlow.pressure:  # the faces hold the fault's pressure
                self.loads.add_on_facets(domain.fault_faces(name), lambda marker: F.compile("L_flow_pressure", marker),
                                         F["p_boundary"], [f.pressure])

    def keep_loads(self, times):
        """Keeps the loads of the last `times` solve times (q for a multirate
        window, whose iterations revisit its fine times; 1 by default)."""
        self.loads.keep(times)

    def fields(self, W):
        """The flux and pressure DOFs of W (owned, global numbering): the
        splits of an iterative solve."""
        index_map = W.dofmap.index_map  # block size 1
        return [Field("flux", owned_global_dofs(index_map, self.Z_to_W)),
                Field("pressure", owned_global_dofs(index_map, self.Q_to_W))]

    def solve(self, t):
        """(z, p) at time t from the coupling data; leaves p in `pressure`:
        b = loads - ((S+L)/dt) p^{n+1,m-1} - (L/dt)(p^{n,m} - p^{n,m-1})
              + (alpha/(q dt)) div(u^n - u_K), tested with th."""
        start = time.perf_counter()
        self.b.x.array[:] = self.loads.at(t).x.array
        if self.u_iterate is not None:
            self.dp.x.array[:] = self.p_iterate.x.array - self.p_iterate_previous.x.array
            self.du.x.array[:] = self.u_iterate.x.array - self.u_window.x.array
        for _, A, x in self.operators:
            multiply_add(A, x, self.b)
        if self.fault_aperture and self.fine_step == 1:
            self.update_apertures()
        if self.conduits:
            self.conduits.load(self._fine_step(t), self.fault_pressure_previous, self.fault_pressure,
                               self.system.appended.b)
        self.assembly_time += time.perf_counter() - start

        self.system.solve(self.b.vector, self.w.vector)
        self.w.x.scatter_forward()
        self.set_unknowns(self.w.x.array)

    def advance(self, t, d):
        """One solve per step: the pressure history of `d` from the last
        step's pressure and p_before, then solve(t)."""
        self.derivative = d
        self.p_previous.x.array[:] = history_value(d, self.pressure.x.array, self.p_before.x.array)
        self.recorded_solve(True, lambda: self.solve(t))

    def solve_fields(self):
        """p, and the conduit faults' p_f (this rank's entries)."""
        p_f = FieldValues(self.fault_pressure, len(self.fault_pressure)) if self.conduits else FieldValues()
        return SolveFields(FieldValues(self.pressure.x.array, owned(self.Q)), FieldValues(), p_f, self.Q.mesh.comm)

    def name(self):
        return "flow" if self.flow_pass == FlowPass.first else "flow_second_pass"

    def state(self):
        return StepState(self.unknowns().copy(), self.pressure.x.array.copy())

    def pin_flipped(self):
        """ConduitFaults.pin_flipped (0 without conduit faults)."""
        return self.conduits.pin_flipped() if self.conduits else 0

    def turn_contradicted_pins(self):
        """ConduitFaults.turn_contradicted_pins (False without conduit faults)."""
        return bool(self.conduits) and self.conduits.turn_contradicted_pins()

    def turn_pins(self):
        """ConduitFaults.turn_pins."""
        if self.conduits:
            self.conduits.turn_pins()

    def release_pins(self):
        """ConduitFaults.release_pins."""
        if self.conduits:
            self.conduits.release_pins()

    def begin_step(self):
        """The conduit faults' pressure now is p_f^old of every solve of the
        step (the split's iterations re-solve it); their iterates' open cells
        start anew."""
        self.fault_pressure_previous[:] = self.fault_pressure
        self.conduits.begin_step()

    def keep_history(self, start):
        """p_before takes the accepted step's start pressure."""
        self.p_before.x.array[:] = start.p

    def accept(self, t):
        """The conduit faults' volumes take the accepted step to t."""
        if self.conduits and self.flow_pass == FlowPass.first:
            fine = self._fine_step(t)
            self.conduits.add_volumes(self.conduits.step_volumes(self.w.x.array, self.fault_pressure,
                                                                 self.fault_pressure_previous, fine), fine,
                                      self.fault_pressure_previous)
            self.conduits.set_intersection_rates(self.fault_pressure)

    def unbalanced(self, t):
        """A conduit fault whose volumes the step to t would leave
        unbalanced (ConduitFaults.unbalanced), or empty."""
        if not self.conduits or self.flow_pass != FlowPass.first:
            return ""
        w = self.w.x.array
        return self.conduits.unbalanced(
            self.conduits.step_volumes(w, self.fault_pressure, self.fault_pressure_previous, self._fine_step(t)),
            largest_entry(w, self.Z_to_W, self.Z.mesh.comm))

    def _fine_step(self, t):
        """The fine step of the next solve or accept, ending at t."""
        return FineStep(t, float(self.F["dt"].value), self.fine_step, int(round(float(self.F["q"].value))),
                        self.derivative.coefficients())

    def set_time_derivative(self, d):
        """The time derivative of the split's steps (advance sets its own):
        the conduit faults' storage differentiates with it as the rock's."""
        self.derivative = d

    def set_fine_step(self, m, previous, iterate):
        """The next solve (or accept) is fine step m of its window (1 for the
        single-rate split), its conduit faults' p_f^old `previous`,
        p_f^{n+1,m-1} (this rank's entries), and `iterate` the reference of
        their fixed-stress term, p_f^{n,m} - p_f^{n,m-1} + p_f^{n+1,m-1}
        (p_f^n when q = 1), the fine-step form of the rock's L (p^{n,m} -
        p^{n,m-1}) (paper eq. 4.17). The apertures are read at fine step 1
        only: the mechanics iterate is the window's."""
        self.fine_step = m
        self.fault_pressure_previous[:] = previous
        self.fault_pressure[:] = iterate

    def fault_volumes(self):
        """The conduit faults' volumes since the run's start (every rank;
        none without conduit faults)."""
        return self.conduits.volumes()

    def fault_intersections(self):
        """Where the conduit faults meet, and the rates through (every rank)."""
        return self.conduits.intersection_rates()

    def history(self):
        """BDF2: p_before, u_before, u_path_before (u_before with coupling.q =
        "auto" too: the last window's change of u); none for the second pass."""
        if self.flow_pass == FlowPass.second:
            return []
        c = self.scene.coupling
        bdf2, q_auto = self.scene.time_scheme == TimeScheme.bdf2, c is not None and c.q_auto
        h = [("pressure_before", self.p_before)] if bdf2 else []
        if (bdf2 or q_auto) and self.u_before is not None:
            h.append(("displacement_before", self.u_before))
        if bdf2 and self.u_before is not None:
            h.append(("displacement_path_before", self.u_path_before))
        return h

    def pressure_values(self):
        return self.pressure.x.array

    def unknowns(self):
        """The mixed solution (z, p) of the last solve, and after it the
        conduit faults' pressure (a copy then)."""
        if self.conduits:
            return np.concatenate([self.w.x.array, self.fault_pressure])
        return self.w.x.array

    def parts(self):
        """The fields within unknowns(), for a checkpoint (none for the second
        pass, which every window computes anew: a checkpoint keeps nothing of it)."""
        if self.flow_pass == FlowPass.second:
            return []
        return [UnknownsPart("flux", self.Z, self.Z_to_W), UnknownsPart("pressure", self.Q, self.Q_to_W)]

    def time_step_changed(self):
        """The matrix and the operators depend on dt: reassembled after
        set_time_step changed it."""
        self.system.reassemble()
        if self.conduits:
            self.append_conduits()
        start = time.perf_counter()
        for a, A, _ in self.operators:
            reassemble_operator(A, a, self.bcs)
        self.assembly_time += time.perf_counter() - start

    def window_steps_changed(self):
        """Only the displacement term, alpha/(q dt) div, depends on q:
        reassembled after set_window_steps changed it (no refactorisation)."""
        start = time.perf_counter()
        for a, A, x in self.operators:
            if x is self.du:
                reassemble_operator(A, a, self.bcs)
        self.assembly_time += time.perf_counter() - start

    def set_unknowns(self, w):
        """Restores a mixed solution (the multirate scheme keeps one per fine
        step), the conduit faults' pressure after it."""
        n = len(self.w.x.array)
        if len(w) > n:
            self.fault_pressure[:] = w[n:]
        if w is not self.w.x.array:
            self.w.x.array[:] = w[:n]
        self.pressure.x.array[:] = w[self.Q_to_W]

    def arrays(self):
        """The conduit faults' pressure, "fault_pressure" (every rank's copy),
        their volumes, "fault_volumes" (4 per fault), and their hydraulic
        apertures at the step's start, "fault_apertures"."""
        if not self.conduits or self.flow_pass == FlowPass.second:
            return {}
        return self.conduits.arrays(self.fault_pressure)

    def restore_arrays(self, arrays):
        if not self.conduits or self.flow_pass == FlowPass.second:
            return
        self.conduits.restore_arrays(arrays, self.fault_pressure)

    def fault_flow(self, t):
        """The conduit faults' cell fields at time t on rank 0
        (ConduitFaults.cell_values; None without conduit faults; collective)."""
        if not self.conduits:
            return None
        return self.conduits.cell_values(self.w.x.array, self.fault_pressure, t)

    def flux(self, out):
        """Cell averages of z: the RT0 field is linear on a cell, its value at
        the midpoint (the DG0 interpolation point) is its average."""
        self.z.x.array[:] = self.w.x.array[self.Z_to_W]
        out.interpolate(self.z)

