"""The mechanics step: the displacement for a given pressure, with contact
(cpp/steps/mechanics_step.cpp)."""
import time

import numpy as np
from dolfinx import fem

from ..contact.locate_contact import locate_contact
from ..contact.bonds import cohesive
from ..contact.contact_state import ActiveSet, ContactState, pair_tractions, same_active_set
from ..contact.contact_set import make_contact_fields, pair_shear_moduli
from ..assembly.loads import Loads
from ..assembly.materials import BodyForceTerm, add_body_force
from ..assembly.parameters import interpolate
from ..domain.domain import pore_pressure_faces
from ..assembly.linear_algebra import (UnknownsPart, assemble_operator, finish_rhs, multiply_add, owned,
                                       rigid_body_modes)
from ..solvers.solver import Method, Structure, SystemLayout
from .solve_record import FieldValues, SolveFields
from .step import Step, StepState
from .system import System
from ..assembly.boundary_conditions import displacement_bcs, update
from .seismic_moments import SeismicMoments, keep_moments, moments_of, record_moments, restore_moments


class MechanicsStep(Step):
    """a(u, v) - (alpha p, div v) = loads, with p the flow pressure (None
    without flow); a linear solve, or the contact VI."""

    def __init__(self, problem, V, pressure):
        """`V` is the P1 displacement space; `pressure` the pore pressure of a
        coupled scene, None otherwise (then the step makes `given_pressure`
        from mechanics.pore_pressure, if the scene gives one)."""
        super().__init__()
        scene, domain, F = problem.scene, problem.domain, problem.forms
        self.scene, comm = scene, domain.mesh.comm
        self.V = V
        self.u = fem.Function(V)
        # Dirichlet conditions, one per prescribed component of each boundary.
        self.bcs, self.bc_values = displacement_bcs(scene, domain, V)
        self.a = F.compile("a_elastic")
        self.make_loads(domain, F)
        # One-way coupling: the pressure is given (mechanics.pore_pressure),
        # taken in P0 at the cell midpoints as the flow's would be, and loads
        # the skeleton through the same operator as the flow's; at the time
        # of the last solve.
        self.given_pressure = None
        if pressure is None and scene.mechanics.pore_pressure is not None:
            self.given_pressure = pressure = fem.Function(F["Q"])
            interpolate(pressure, [scene.mechanics.pore_pressure], 0.0)
        # The pressure load (alpha p, div v), applied as an operator on p.
        self.pressure = pressure
        self.pressure_load = assemble_operator(F.compile("a_pressure_load", pore_pressure_faces(scene, domain)),
                                               self.bcs) \
            if pressure is not None else None

        self.assembly_time = 0.0  # right-hand sides
        # a(u, v) never changes: assembled once; SPD with identity Dirichlet rows.
        self.system = System(comm, self.a, self.bcs, SystemLayout("mechanics_", Structure.spd), scene.solver.mechanics)
        if self.system.method == Method.iterative:
            self.system.set_near_nullspace(rigid_body_modes(V))
        self.b = fem.Function(V)
        self.fault_load = None  # (FaultAperture, p_f): the conduit faults' pressure on their faces
        # Whether a conduit fault's aperture follows its normal stress; and
        # the conduit cells' effective normal stress s_n at the last solve,
        # the mean contact traction of their pairs (FaultAperture.cell_means;
        # every cell on every rank), computed only then.
        self.closure = any(f.closure is not None for f in scene.faults.values())
        self.fault_traction = np.zeros(0)
        self.contact_pressure = self.contact_active = self.contact_boundary = None
        self.moments = SeismicMoments()
        if scene.has_contact():
            self.attach_contact(domain, F)

    def make_loads(self, domain, F):
        """Body force, tractions (also on a loaded contact boundary) and the
        faults' pressures, in that order, lifted and with their Dirichlet
        values at t."""
        def finish(b, t):
            update(self.bc_values, t)
            finish_rhs(b, self.a, self.bcs)
        self.loads = Loads(self.V, finish)
        for expression, *_ in self.bc_values:
            self.loads.depends_on_time(expression.depends_on_time)
        add_body_force(self.loads, self.scene, domain, F, BodyForceTerm("L_body_force", "L_body_force_cells"))
        for name, b in self.scene.boundaries.items():
            if b.traction:
                self.loads.add_boundary(domain, name, lambda marker: F.compile("L_traction", marker),
                                        F["traction"], b.traction)
        self._add_fault_pressures(domain, F)

    def _add_fault_pressures(self, domain, F):
        """A fault's fluid pressure pushing on both its faces (fault.NAME.pressure),
        through the data coefficient p_boundary (P1) the loads fill in turn."""
        for name, f in self.scene.faults.items():
            if f.pressure is not None:
                self.loads.add_on_facets(domain.fault_faces(name), lambda marker: F.compile("L_face_pressure", marker),
                                         F["p_boundary"], [f.pressure])

    def attach_contact(self, domain, F):
        """Contact: a bound for each constraint u.nu_F <= g_a of Gamma_3 (contact.py)."""
        contact_set = locate_contact(self.scene, domain, F, self.V)
        contact_set.shear_modulus = pair_shear_moduli(contact_set, self.V, F["G"])
        self.moments = moments_of(contact_set)
        self.contact_pressure, self.contact_active, self.contact_boundary = make_contact_fields(contact_set)
        # the mechanics alone over one step solves the contact once
        once = self.scene.flow is None and not self.scene.adaptive and self.scene.num_steps() == 1
        self.system.use_contact(contact_set, np.arange(owned(self.V)), (), once)

    def assemble_rhs(self, t):
        """The loads change with t only; the pressure load changes every
        iteration: one product with its operator, whose Dirichlet rows are zero."""
        self.b.x.array[:] = self.loads.at(t).x.array
        if self.given_pressure is not None:
            interpolate(self.given_pressure, [self.scene.mechanics.pore_pressure], t)
        if self.pressure_load:
            multiply_add(self.pressure_load, self.pressure, self.b)
        if self.fault_load:
            aperture, p_f = self.fault_load
            aperture.add_load(p_f, self.bcs, self.b)

    def load_fault_pressure(self, aperture, p_f):
        """The conduit faults' pressure p_f (this rank's entries) pushes
        their faces apart at every solve from now on, by the load of the
        FaultAperture `aperture`."""
        self.fault_load = (aperture, p_f)

    def solve(self, t):
        """Solves at time t with the current pressure; leaves the result in u."""
        start = time.perf_counter()
        self.assemble_rhs(t)
        self.assembly_time += time.perf_counter() - start
        self.system.solve(self.b.vector, self.u.vector)
        self.u.x.scatter_forward()
        if self.closure and self.fault_load:
            self.fault_traction = self.fault_load[0].cell_means(pair_tractions(self.contact_state()))

    def name(self):
        return "mechanics"

    def accept(self, t):
        """The accepted step's seismic moment, per fault
        (FaultSummary.moment), joins the run's record."""
        self.system.accept_step(self.u.vector)
        if self.moments.names:  # no fault: nothing to record, no contact state computed
            record_moments(self.moments, t, self.contact_state())

    def arrays(self):
        """The record of the faults' seismic moments, "seismic_moments" (a
        checkpoint's), the conduit cells' s_n, "fault_traction", and with
        cohesion the broken bonds, "broken_bonds"."""
        arrays = {}
        keep_moments(self.moments, arrays)
        if len(self.fault_traction):
            arrays["fault_traction"] = np.array(self.fault_traction)
        if self.system.contact and cohesive(self.system.contact.set):
            arrays["broken_bonds"] = np.array(self.system.contact.broken_bonds())
        return arrays

    def restore_arrays(self, arrays):
        restore_moments(self.moments, arrays)
        if "broken_bonds" in arrays:
            self.system.contact.restore_bonds(arrays["broken_bonds"])
        if "fault_traction" in arrays:
            self.fault_traction = np.array(arrays["fault_traction"])

    def seismic_moments(self):
        """The faults' seismic moments of every accepted step
        (SeismicMoments)."""
        return self.moments

    def advance(self, t, d):
        """solve(t): the mechanics has no time derivative."""
        self.recorded_solve(True, lambda: self.solve(t))

    def solve_fields(self):
        return SolveFields(FieldValues(), FieldValues(self.u.x.array, owned(self.V)), FieldValues(), self.V.mesh.comm)

    def equilibrate(self):
        """The solve at t = 0."""
        self.advance(0.0, None)
        return self.solves()

    def begin_step(self):
        self.system.begin_step(self.u.vector)

    def state(self):
        return StepState(self.u.x.array.copy())

    def unknowns(self):
        return self.u.x.array

    def set_unknowns(self, x):
        self.u.x.array[:] = x

    def parts(self):
        return [UnknownsPart("displacement", self.V)]

    def displacement_values(self):
        return self.u.x.array

    def same_contact_set(self, before):
        return same_active_set(self.active_contact_set(), before, self.V.mesh.comm)

    def has_contact(self):
        return self.system.has_contact()

    def active_contact_set(self):
        """Only the contact active set of u, for the log of every iteration
        (empty without contact)."""
        return self.system.contact.active_set(self.u.vector) if self.system.has_contact() else ActiveSet()

    def active_set_changes(self):
        """Changes of the contact active set so far (0 without contact)."""
        return self.system.contact.active_set_changes if self.system.has_contact() else 0

    def contact_state(self):
        """Also fills the contact pressure and active-flag fields."""
        if not self.system.has_contact():
            return ContactState()
        return self.system.contact.state(self.u.vector, self.b.vector, self.contact_pressure,
                                         self.contact_active)

    def pin_contact(self, pins):
        """ContactSolver.pin (collective; none without contact)."""
        if self.system.has_contact():
            self.system.contact.pin(pins)

    def consistent_pins(self):
        """ContactSolver.consistent_pins at the current u (collective; none
        without contact)."""
        if not self.system.has_contact():
            return np.zeros(0, dtype=np.int8)
        return self.system.contact.consistent_pins(self.u.vector, self.b.vector)
