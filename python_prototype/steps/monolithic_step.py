"""The monolithic step: flux, pressure and displacement solved together
(cpp/steps/monolithic_step.cpp). Conduit faults append their pressure p_f
(monolithic_conduits.py), and each step iterates on their apertures."""
import time

import numpy as np
from dolfinx import fem

from ..contact.locate_contact import locate_contact
from ..contact.bonds import cohesive
from ..contact.contact_state import ActiveSet, ContactState, same_active_set
from ..contact.contact_set import make_contact_fields, pair_shear_moduli
from ..solvers.field_split import Field, part_of
from ..assembly.loads import Loads
from ..assembly.materials import BodyForceTerm, add_body_force
from ..domain.domain import pore_pressure_faces
from ..scene.input import FaultFlow, TimeScheme
from ..assembly.parameters import interpolate
from ..assembly.linear_algebra import (UnknownsPart, add_vector, dof_map, finish_rhs, largest_entry, owned,
                                       owned_global_dofs, rigid_body_modes)
from ..solvers.solver import SolverError, Structure, SystemLayout
from .mechanics_step import MechanicsStep
from .monolithic_conduits import MixedSpace, MonolithicConduits
from .seismic_moments import SeismicMoments, keep_moments, moments_of, record_moments, restore_moments
from .solve_record import FieldValues, SolveFields
from .step import Step, StepState
from .system import System
from ..assembly.boundary_conditions import displacement_bcs, facet_flux, fault_flux_ties, flux_bc, update, update_fluxes
from ..assembly.wells import add_wells, depends_on_time, well_sources
from ..time.time_scheme import TimeDerivative, history_value


class MonolithicStep(Step):
    """(u, z, p) together on P1^d x RT0 x P0, one VI per step."""

    def __init__(self, problem):
        super().__init__()
        scene, domain, F = problem.scene, problem.domain, problem.forms
        self.problem, self.scene, comm = problem, scene, domain.mesh.comm
        X = F["X"]
        self.V, self.Q = F["V"], F["Q"]
        self.V_to_X, self.Q_to_X = dof_map(self.V, X.sub(0)), dof_map(self.Q, X.sub(2))
        self.Z, self.Z_to_X = X.sub(1).collapse()
        self.x, self.z = fem.Function(X), fem.Function(self.Z)
        self.u, self.pressure = fem.Function(self.V), fem.Function(self.Q)
        self.u_old, self.p_old = F["u_old"], F["p_old"]
        self.u_before, self.p_before = fem.Function(self.V), fem.Function(self.Q)  # BDF2's memory; checkpointed
        self.derivative = TimeDerivative()  # of the step being solved
        interpolate(self.pressure, [scene.flow.initial_pressure], 0.0)
        self.x.x.array[self.Q_to_X] = self.pressure.x.array  # the first guess of a contact solve

        # Essential conditions: displacement components on X.sub(0), no flow on X.sub(1).
        self.bcs, self.bc_values = displacement_bcs(scene, domain, X.sub(0))
        bc, self.fluxes = flux_bc(scene, domain, X.sub(1))
        self.bcs.append(bc)
        faces = pore_pressure_faces(scene, domain)  # the face term of the operator
        self.a = F.compile("a_monolithic", faces)
        self.L_history = F.compile("L_monolithic_history")
        self.make_loads(domain, F)

        self.assembly_time = 0.0  # right-hand sides
        # Depends on dt only; its pressure block -(S/dt) is often negligible
        # against the coupling: LU with pivoting (cpp/steps/monolithic_step.cpp). The
        # iterative path is preconditioned by the fixed-stress split (the
        # conduit faults' p_f joins the flow: System.append).
        self.system = System(comm, self.a, self.bcs, SystemLayout("monolithic_", Structure.general, self.fields(X)),
                             scene.solver.monolithic,
                             F.compile("a_monolithic_preconditioner", faces))
        flux = facet_flux(F, "L_monolithic_pressure", "X")
        self.system.tie(fault_flux_ties(scene, domain, X.sub(1), flux))
        self.b = fem.Function(X)
        self.contact_pressure = self.contact_active = self.contact_boundary = None
        self.moments = SeismicMoments()
        # p_f before the contact: the contact solver takes the appended system
        self.conduits = MonolithicConduits(problem, MixedSpace(X, self.V, self.V_to_X, self.bcs, flux))
        self.fault_traction = None  # s_n per conduit cell at the last solve (with a closure)
        if self.conduits:
            self.conduits.append(self.system)
        if scene.has_contact():
            self.attach_contact(domain, F)

    def make_loads(self, domain, F):
        """Body force, tractions, source, boundary pressures, gravity and the
        faults' pressures (on both faces, and as a boundary pressure of a
        fault held at it), in that order, with the Dirichlet values at t
        (lifted with the history term, assemble_rhs)."""
        scene = self.scene
        def finish(b, t):
            add_wells(self.wells, t, b.x.array)
            update(self.bc_values, t)
            update_fluxes(self.fluxes, t)
        self.loads = Loads(F["X"], finish)
        for expression, *_ in self.bc_values:
            self.loads.depends_on_time(expression.depends_on_time)
        for f in self.fluxes.boundaries:
            self.loads.depends_on_time((f.rate or f.flux).depends_on_time)
        self.wells = well_sources(scene, domain, self.Q, self.Q_to_X)
        self.loads.depends_on_time(depends_on_time(self.wells))
        add_body_force(self.loads, scene, domain, F,
                       BodyForceTerm("L_monolithic_body_force", "L_monolithic_body_force_cells"))
        for name, b in scene.boundaries.items():
            if b.traction:  # a traction boundary, or a loaded contact boundary
                self.loads.add_boundary(domain, name, lambda m: F.compile("L_monolithic_traction", m),
                                        F["traction"], b.traction)
        if scene.flow.source:
            self.loads.add(F.compile("L_monolithic_source"), F["source"], [scene.flow.source])
        for name, b in scene.boundaries.items():
            if b.flow == "pressure":
                self.loads.add_boundary(domain, name, lambda m: F.compile("L_monolithic_pressure", m),
                                        F["p_boundary"], [b.pressure])
        if scene.flow.gravity:
            self.loads.add(F.compile("L_monolithic_gravity"))
        for name, f in scene.faults.items():
            if f.pressure is None:
                continue
            # The fault's fluid pressure on both its faces, and its flow condition.
            forms = ["L_monolithic_face_pressure"]
            if f.flow == FaultFlow.pressure:
                forms.append("L_monolithic_pressure")
            for form in forms:
                self.loads.add_on_facets(domain.fault_faces(name), lambda m: F.compile(form, m),
                                         F["p_boundary"], [f.pressure])

    def attach_contact(self, domain, F):
        """Contact: the bounds sit on DOFs of the displacement block (contact.py)."""
        contact_set = locate_contact(self.scene, domain, F, self.V)
        contact_set.shear_modulus = pair_shear_moduli(contact_set, self.V, F["G"])
        self.moments = moments_of(contact_set)
        displacement = self.V_to_X[:owned(self.V)]
        if np.any(displacement >= owned(F["X"])):
            raise RuntimeError("monolithic contact: a displacement DOF owned in V is not owned in the mixed space")
        self.contact_pressure, self.contact_active, self.contact_boundary = make_contact_fields(contact_set)
        # the pressure rows are the rock's mass balances
        balances = self.Q_to_X[self.Q_to_X < owned(F["X"])]
        self.system.use_contact(contact_set, displacement, balances)

    def fields(self, X):
        """The splits of (u, z, p) for the fixed-stress preconditioner: the
        flow (flux, pressure), then the mechanics node by node with the
        rigid-body modes in its numbering (cpp/steps/monolithic_step.cpp)."""
        comm, index_map = X.mesh.comm, X.dofmap.index_map  # block size 1
        z, p = owned_global_dofs(index_map, self.Z_to_X), owned_global_dofs(index_map, self.Q_to_X)
        u = owned_global_dofs(index_map, self.V_to_X)
        flow = Field("flow", np.sort(np.concatenate([z, p])))
        flow.fields = [part_of(flow, "flux", z, comm), part_of(flow, "pressure", p, comm)]
        position = np.searchsorted(u, index_map.local_range[0] + self.V_to_X[:owned(self.V)])
        mechanics = Field("mechanics", u, self.V.dofmap.index_map_bs, rigid_body_modes(self.V, position))
        return [flow, mechanics]

    def assemble_rhs(self, t):
        """The right-hand side of a step to t from the state in u and pressure."""
        start = time.perf_counter()
        # Backward Euler from the previous state, or BDF2's history values.
        self.u_old.x.array[:] = history_value(self.derivative, self.u.x.array, self.u_before.x.array)
        self.p_old.x.array[:] = history_value(self.derivative, self.pressure.x.array, self.p_before.x.array)
        self.b.x.array[:] = self.loads.at(t).x.array
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

    def solve(self, t, derivative=TimeDerivative()):
        """One step to time t from the state in u and pressure with the time
        derivative of the accumulation (time_scheme.py; BDF2 reads u_before
        and p_before, the state one step before)."""
        self.derivative = derivative
        self.assemble_rhs(t)
        if self.conduits:
            self.conduits.set_time_derivative(self.system, derivative)
            self._solve_with_conduits(t)
        else:
            self.recorded_solve(True, self._solve_system)

    def solve_fields(self):
        """p, u and the conduit faults' p_f (this rank's entries)."""
        p_f = FieldValues(self.conduits.pressure, len(self.conduits.pressure)) if self.conduits else FieldValues()
        return SolveFields(FieldValues(self.pressure.x.array, owned(self.Q)), FieldValues(self.u.x.array, owned(self.V)),
                           p_f, self.V.mesh.comm)

    def _solve_system(self):
        """Solves the system at the right-hand side assembled; u, pressure and
        p_f from its solution."""
        self.system.solve(self.b.vector, self.x.vector)
        self.x.x.scatter_forward()
        self.u.x.array[:] = self.x.x.array[self.V_to_X]
        self.pressure.x.array[:] = self.x.x.array[self.Q_to_X]

    def _aperture_iteration(self, t):
        """One solve with the conduit faults' last apertures; whether they
        settled."""
        self.conduits.load(self.system, self.x.vector, t)
        self._solve_system()
        self.fault_traction = self._fault_normal_stress()
        return self.conduits.update(self.system, self.u, self.fault_traction)

    def _solve_with_conduits(self, t):
        """Iterates on the conduit faults' apertures (monolithic_conduits.py)
        until they settle; raises SolverError after coupling.max_iterations."""
        most = self.scene.coupling.max_iterations
        for i in range(1, most + 1):
            # Newton's term of the transmissibilities only speeds the iteration
            # up: where the contact solve fails with it, the same iterate is
            # solved again without it (cpp/steps/monolithic_step.cpp)
            iterate = np.array(self.unknowns()) if self.conduits.newton() else None
            try:
                if self.recorded_solve(i == 1, lambda: self._aperture_iteration(t)):
                    return
            except SolverError:
                if iterate is None or i == most:
                    raise
                self.set_unknowns(iterate)
                self.conduits.drop_newton(self.system)
        raise SolverError(f"monolithic: the conduit faults' apertures still move after {most} iterations "
                          f"(coupling.max_iterations): {self.conduits.last_change()}")

    def _fault_normal_stress(self):
        """The conduit cells' s_n now, with a closure (None otherwise)."""
        if not self.conduits.has_closure():
            return None
        return self.conduits.normal_stress(self.contact_state())

    def name(self):
        return "monolithic"

    def advance(self, t, d):
        self.solve(t, d)

    def equilibrate(self):
        """The coupled system has no mechanics system of its own: one
        mechanics step on its displacement space, loaded by its pressure,
        solved once."""
        step = MechanicsStep(self.problem, self.V, self.pressure)
        if self.conduits:  # the conduit faults' pressure on their faces too
            step.load_fault_pressure(self.conduits.aperture, self.conduits.pressure)
        records = step.equilibrate()
        self.set_displacement(step.u.x.array, 0.0)
        self.fault_traction = step.fault_traction
        return records

    def begin_step(self):
        if self.conduits:
            self.conduits.begin_step(self.system, self.u, self.fault_traction)
        self.system.begin_step(self.x.vector)

    def state(self):
        return StepState(self.unknowns().copy(), self.pressure.x.array.copy(), self.u.x.array.copy())

    def keep_history(self, start):
        """p_before and u_before take the accepted step's start."""
        self.p_before.x.array[:] = start.p
        self.u_before.x.array[:] = start.u

    def history(self):
        """BDF2: p_before and u_before."""
        if self.scene.time_scheme != TimeScheme.bdf2:
            return []
        return [("pressure_before", self.p_before), ("displacement_before", self.u_before)]

    def accept(self, t):
        """The accepted step's seismic moment, per fault, joins the run's
        record."""
        self.system.accept_step(self.x.vector)
        if self.moments.names:  # no fault: nothing to record, no contact state computed
            record_moments(self.moments, t, self.contact_state())
        if self.conduits:
            self.conduits.accept(self.x.x.array, t)

    def unbalanced(self, t):
        """A conduit fault the step to t would leave unbalanced, or empty."""
        if not self.conduits:
            return ""
        x = self.x.x.array
        return self.conduits.unbalanced(x, t, largest_entry(x, self.Z_to_X, self.Z.mesh.comm))

    def fault_flow(self, t):
        """The conduit faults' cell fields at t on rank 0 (FlowStep.fault_flow;
        None without conduits)."""
        return self.conduits.cell_values(self.x.x.array, t) if self.conduits else None

    def fault_volumes(self):
        """The conduit faults' volumes since the run's start (none without)."""
        return self.conduits.volumes() if self.conduits else []

    def fault_intersections(self):
        """Where the conduit faults meet, and the rates through (FlowStep's)."""
        return self.conduits.intersection_rates() if self.conduits else []

    def arrays(self):
        """The record of the faults' seismic moments, "seismic_moments" (a
        checkpoint's), the conduit faults' arrays (FlowStep.arrays), their
        cells' s_n, "fault_traction", and with cohesion the broken bonds,
        "broken_bonds"."""
        arrays = {}
        keep_moments(self.moments, arrays)
        if self.conduits:
            self.conduits.keep(arrays)
        if self.fault_traction is not None and len(self.fault_traction):
            arrays["fault_traction"] = np.asarray(self.fault_traction)
        if self.system.contact and cohesive(self.system.contact.set):
            arrays["broken_bonds"] = np.array(self.system.contact.broken_bonds())
        return arrays

    def restore_arrays(self, arrays):
        restore_moments(self.moments, arrays)
        if "broken_bonds" in arrays:
            self.system.contact.restore_bonds(arrays["broken_bonds"])
        if self.conduits:
            self.conduits.restore(arrays)
        if "fault_traction" in arrays:
            self.fault_traction = np.asarray(arrays["fault_traction"])

    def seismic_moments(self):
        """The faults' seismic moments of every accepted step."""
        return self.moments

    def pressure_values(self):
        return self.pressure.x.array

    def displacement_values(self):
        return self.u.x.array

    def same_contact_set(self, before):
        return same_active_set(self.active_contact_set(), before, self.V.mesh.comm)

    def has_contact(self):
        return self.system.has_contact()

    def time_step_changed(self):
        """The matrix depends on dt: reassembled after set_time_step changed it."""
        self.system.reassemble()
        if self.conduits:
            self.conduits.append(self.system)

    def flux(self, out):
        self.z.x.array[:] = self.x.x.array[self.Z_to_X]
        out.interpolate(self.z)

    def unknowns(self):
        """The coupled unknown (u, z, p), ghosts included, then the conduit
        faults' p_f (this rank's entries), for a checkpoint."""
        if not self.conduits:
            return self.x.x.array
        return np.concatenate([self.x.x.array, self.conduits.pressure])

    def parts(self):
        """The fields within unknowns(), for a checkpoint."""
        return [UnknownsPart("displacement", self.V, self.V_to_X), UnknownsPart("flux", self.Z, self.Z_to_X),
                UnknownsPart("pressure", self.Q, self.Q_to_X)]

    def set_unknowns(self, x):
        """Loads unknowns() back (and u, pressure from it)."""
        n = len(self.x.x.array)
        if len(x) > n:
            self.conduits.pressure = np.array(x[n:])
        self.x.x.array[:] = x[:n]
        self.u.x.array[:] = self.x.x.array[self.V_to_X]
        self.pressure.x.array[:] = self.x.x.array[self.Q_to_X]

    def active_contact_set(self):
        """Only the contact active set (collective, cheap; empty without contact)."""
        if not self.system.has_contact():
            return ActiveSet()
        return self.system.contact.active_set(self.system.whole(self.x.vector, self.b.vector)[0])

    def contact_state(self):
        if not self.system.has_contact():
            return ContactState()
        x, b = self.system.whole(self.x.vector, self.b.vector)
        return self.system.contact.state(x, b, self.contact_pressure, self.contact_active)


