"""The fields written at each output time: the unknowns and what is derived
from them (cell-averaged flux, volumetric stress sigma_v, contact);
cpp/output/fields.h."""
from dolfinx import fem

from ..contact.contact_state import ContactState
from ..diagnostics.diagnostics import volumetric_stress
from .fault_series import FaultSeries


def _name_fields(scheme):
    """The names ParaView shows."""
    if scheme.p is not None:
        scheme.p.name = "pressure"
    if scheme.u is not None:
        scheme.u.name = "displacement"
    if scheme.contact_pressure is not None:
        scheme.contact_pressure.name = "contact_pressure"
        scheme.contact_active.name = "contact_active"


class OutputFields:
    """Writes the scheme's fields into the output at a time; names them as
    ParaView shows them."""

    def __init__(self, problem, scheme, output, resume_time=None):
        """With faults and XDMF output, the faults' fields go to fault.xdmf
        (kept up to `resume_time` after a restart)."""
        F = problem.forms
        self._F, self._output = F, output
        self.read_from(scheme)
        if scheme.p is not None:
            self._flux = fem.Function(F["Qv"], name="flux")
        if scheme.u is not None:
            self._sigma_v = fem.Function(F["Q"], name="sigma_v")
            self._L_sigma_v = F.compile("L_sigma_v")
        self._faults, self._fault_flow = None, None
        if problem.scene.faults and problem.scene.write_xdmf:
            self._faults = FaultSeries(problem.domain.mesh.comm, output.directory(), problem, resume_time)
        self.contact = ContactState()  # at the last mechanics output

    def read_from(self, scheme):
        """The scheme whose fields are written from now on: the run's, or
        coupling.fallback's for the step it solved."""
        _name_fields(scheme)
        self._scheme = scheme

    def read_contact(self):
        """`contact` from the scheme, where its fields are not written."""
        self.contact = self._scheme.contact_state()

    def write_flow(self, t):
        """The pressure and the flux (nothing without flow)."""
        s = self._scheme
        if s.p is None:
            return
        self._output.write(s.p, t)
        s.flux(self._flux)
        self._output.write(self._flux, t)
        self._fault_flow = s.fault_flow(t)
        if self._faults is not None and s.u is None:  # else with the mechanics' fields
            self._faults.write(ContactState(), self._fault_flow, t)

    def write_mechanics(self, t):
        """The displacement, sigma_v and the contact fields; also updates
        `contact`."""
        s = self._scheme
        self.contact = s.contact_state()
        volumetric_stress(self._F, self._L_sigma_v, s.u, s.p if s.p is not None else s.given_pressure,
                          self._sigma_v)
        self._output.write(s.u, t)
        self._output.write(self._sigma_v, t)
        if s.contact_pressure is not None:
            self._output.write(s.contact_pressure, t)
            self._output.write(s.contact_active, t)
        if self._faults is not None:
            self._faults.write(self.contact, self._fault_flow, t)

    def close(self):
        """fault.h5 closed (every write is already on disk)."""
        if self._faults is not None:
            self._faults.close()
