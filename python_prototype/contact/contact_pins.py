"""Pins on the contact's constraints (ContactSolver.pin, contact.py;
cpp/contact/contact_pins.cpp): a constraint pinned closed is held on its
bound, one pinned open has none, as the fixed-stress split asks where its
contact set cycles (coupling/pins.py)."""
import numpy as np
from mpi4py import MPI

from .contact_set import displacement_scale
from .contact_state import contact_pressures

# A pinned constraint contradicts its pin (ContactPins.consistent_pins)
# beyond this fraction of the displacement scale or the largest contact
# pressure: the tolerance of SNES's "on a bound" (variational_inequality.py).
PIN_TOLERANCE = 1e-8


class ContactPins:
    """The pins of ContactSolver (contact.py), its base class: the methods
    below read the contact set, the VI and the contact force it holds."""

    pins = np.zeros(0, dtype=np.int8)  # per constraint of the set (this rank's)
    pinned = False                     # whether any rank has a pin

    def pin(self, pins):
        """From the next solve on, each constraint k of the set (this rank's)
        is pinned closed (pins[k] = 1: on its bound, whatever its force),
        pinned open (-1: unbounded) or free (0); empty on every rank: none
        pinned (collective)."""
        self.pinned = bool(self.comm.allreduce(int(len(pins) > 0), op=MPI.MAX))
        self.pins = np.zeros(len(self.dofs), dtype=np.int8)
        self.pins[:len(pins)] = pins

    def _pins_in_vi(self):
        """The pins in the VI's bounded positions (collective when
        condensed)."""
        if not self.schur:
            return self.pins
        mine = np.zeros(len(self._contact_dofs()))
        mine[:len(self.pins)] = self.pins
        return self.schur.gather(mine)[self.vi.p.bounded].astype(np.int8)

    def consistent_pins(self, x, b):
        """The pins at x under load b, those x contradicts turned: a
        constraint pinned open that penetrates by more than PIN_TOLERANCE of
        the displacement scale is pinned closed, one pinned closed that pulls
        by more than PIN_TOLERANCE of the largest contact pressure is pinned
        open (this rank's; collective)."""
        distance = self.distances(x)
        scale = displacement_scale(self.set, self.displacement_dofs, x, self.comm)
        R = self._contact_force(x, b).getArray(readonly=True)
        pressure = contact_pressures(self.set, self.dofs, R)
        largest = self.comm.allreduce(float(max(pressure.max(initial=0.0), 0.0)), op=MPI.MAX)
        pins = self.pins.copy()
        contradicted = ((pins < 0) & (distance < -PIN_TOLERANCE * scale)) | \
                       ((pins > 0) & (pressure < -PIN_TOLERANCE * largest))
        pins[contradicted] = -pins[contradicted]
        return pins
