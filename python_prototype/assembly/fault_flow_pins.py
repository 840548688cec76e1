"""Pins on the conduit faults' open cells (ConduitFaults, fault_flow.py;
cpp/assembly/fault_flow_pins.cpp): a cell pinned open takes the
fixed-stress term and a hydraulic aperture linear in its opening, one
pinned closed the residual aperture, as the fixed-stress split asks where
its contact set cycles (coupling/pins.py)."""
import numpy as np


class CellPins:
    """A conduit's cells in the step: the changes of each one's open state,
    its pin (-1 pinned open, 1 pinned closed, 0 free), and its mean opening
    w at the last set_openings with the threshold e of an open cell."""

    def __init__(self, n):
        self.flips, self.pins = np.zeros(n, dtype=int), np.zeros(n, dtype=np.int8)
        self.opening, self.threshold = np.zeros(n), 0.0


class ConduitPins:
    """The pins of ConduitFaults (fault_flow.py), its base class: the
    methods below read the faults' cells and open sets that ConduitFaults
    holds."""

    @staticmethod
    def _pinned_openings(conduit, w, e):
        """The open part of w_h and the open cells at the mean openings w:
        (w - e)^+ and w > e where free, w - e and open where pinned open, 0
        and closed where pinned closed; and which cells are free. Counts each
        cell's flips and keeps w (pin_flipped, turn_contradicted_pins)."""
        c = conduit.pinning or CellPins(len(w))  # none before the first step
        is_open = np.where(c.pins == 0, w > e, c.pins < 0)
        opened = np.where(c.pins < 0, w - e, np.where(c.pins > 0, 0.0, np.maximum(w - e, 0.0)))
        c.flips += is_open != conduit.open
        c.opening, c.threshold = np.array(w, dtype=float), e
        return opened, is_open, c.pins == 0

    def pin_flipped(self):
        """The cells whose open state flipped at least twice in the step
        are pinned open from the next set_openings on, open whatever their
        w, with w_h = w_r + b + w - e linear in w; the apertures' relaxation
        starts anew. How many cells are pinned (every rank alike)."""
        pinned = 0
        for c in (conduit.pinning for conduit in self.faults):
            c.pins[(c.pins == 0) & (c.flips >= 2)] = -1
            pinned += int(np.count_nonzero(c.pins))
        # The relaxation that the flips started restarts on the map the pins leave.
        self.relaxing, self.relaxation, self.stalled, self.lags = False, 1.0, 0, []
        return pinned

    def turn_contradicted_pins(self):
        """Each pinned cell whose mean opening at the last set_openings
        contradicts its pin turns it: pinned open with w < -e to pinned
        closed (w_h = w_r + b), pinned closed with w > e to pinned open.
        Whether any turned (every rank alike)."""
        turned = False
        for c in (conduit.pinning for conduit in self.faults):
            contradicted = ((c.pins < 0) & (c.opening < -c.threshold)) | ((c.pins > 0) & (c.opening > c.threshold))
            c.pins[contradicted] = -c.pins[contradicted]
            turned = turned or bool(np.any(contradicted))
        return turned

    def turn_pins(self):
        """Every pin turned (open to closed, closed to open)."""
        for conduit in self.faults:
            conduit.pinning.pins *= -1

    def release_pins(self):
        """No cell pinned from the next set_openings on."""
        for conduit in self.faults:
            if conduit.pinning:
                conduit.pinning.pins[:] = 0
