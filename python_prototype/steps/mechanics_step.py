"""The mechanics step: the displacement for a given pressure, with contact
(cpp/steps/mechanics_step.cpp)."""
import time

import numpy as np
from dolfinx import fem

from ..contact.contact import ContactSet, ContactState, contact_boundary_flag
from ..assembly.parameters import interpolate
from ..assembly.linear_algebra import add_vector, assemble_operator, finish_rhs, multiply_add, owned, rigid_body_modes
from ..solvers.solver import Method, Structure
from ..solvers.system import System
from ..assembly.boundary_conditions import displacement_bcs, update


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


