"""The fixed-stress terms of the conduit faults (ConduitFaults,
fault_flow.py; cpp/assembly/fault_flow_compliance.cpp): each cell's L_f
from the compliances of fault_compliance.py, the open patch's in the split
and the closure's in closed cells, and the term the monolithic system's
fixed-stress preconditioner gives the open cells."""
import numpy as np

from .fault_compliance import closure_compliance, open_patches, patch_compliance


class ConduitCompliance:
    """The fixed-stress terms of ConduitFaults (assembly/fault_flow.py), its
    base class: the methods below read the faults' cells and open sets
    that ConduitFaults holds."""

    @staticmethod
    def _stabilisation(conduit, dt):
        """L_k / dt = L_f |k| / dt in the open cells, 0 in the others."""
        return conduit.compliance * conduit.cells.measures / dt

    def _set_compliance(self, conduit):
        """Each cell's L_f, with L_k = L_f |k| the fault's fixed-stress term
        (Girault, Kumar and Wheeler): in the cells open (w > e) at either of
        the last two mechanics iterates of the step, the mean opening per
        unit pressure of the open patch the cell belongs to
        (patch_compliance); in the other cells the closure's compliance
        -b'(s_n) (closure_compliance: there s_n falls as p_f rises), or 0
        without a closure, where p_f moves nothing. Why not L in every cell,
        and why the cells open at the iterate before keep the patch's L:
        docs/theory.md, "Flow in a fault"."""
        closed = closure_compliance(conduit.closure, conduit.traction) if conduit.closure else 0.0
        L = self._patch_compliances(conduit)
        conduit.compliance = np.where(L >= 0, L, closed)
        if self.implicit:  # the open cells' opening is implicit; closed cells keep their closure's
            conduit.compliance = np.where(conduit.open, 0.0, closed) * np.ones(len(L))
        if not self.stabilised:
            conduit.compliance = np.zeros_like(conduit.compliance)

    def _patch_compliances(self, conduit):
        """Per cell, patch_compliance of the patch of cells open at either of
        the last two mechanics iterates that it belongs to, -1 outside one."""
        patch = open_patches((conduit.cells.links, conduit.cells.cut), conduit.open | conduit.open_before)
        size = np.zeros(len(patch))
        np.add.at(size, patch[patch >= 0], conduit.cells.measures[patch >= 0])
        return np.where(patch >= 0, patch_compliance(size[patch], conduit.modulus, self.dim), -1.0)

    def open_stabilisation(self, dt):
        """Per appended row (this rank's entries) the fixed-stress term L_k/dt =
        L_f |k|/dt that the split gives an open cell (its open patch's
        patch_compliance), 0 in the others: what the monolithic system's
        fixed-stress preconditioner adds to C's diagonal, its open cells
        taking none in the system itself (with_implicit_openings)."""
        s = np.zeros(self.size)
        for conduit in self.faults:
            L = self._patch_compliances(conduit)
            n = len(L)
            s[conduit.offset:conduit.offset + n] = np.where(conduit.open & (L > 0), L, 0.0) * conduit.cells.measures / dt
        return self.rows.entries(s)
