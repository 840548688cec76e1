"""The preconditioner of the Newton steps of the contact VI on the full
system (cpp/solvers/inactive_set_preconditioner.h, which explains the mathematics):
AMG for the mechanics, the fixed-stress sweep for the coupled system.

SNES VI's reduced matrix A_II loses the block size, near-nullspace and
field splits of the system; this preconditioner applies the system's own
preconditioner B to P_D, P (A, or the fixed-stress matrix) with the active
rows and columns made identity rows, which keeps all three, and (P_D)^-1
restricted to the inactive set I is P_II^-1:
B_I^-1 r_I = R_I B(P_D)^-1 R_I^T r_I."""
import time

import numpy as np
from petsc4py import PETSc

from .field_split import set_fields
from .solver import set_default_option


class InactiveSetPreconditioner:
    def __init__(self, snes, P, fields, row_weights, prefix):
        """With `row_weights` W (or None) the Newton steps are of W A: it is
        built from W P."""
        self.snes, self.P, self.row_weights = snes, P, row_weights
        self.setups, self.setup_time = 0, 0.0
        pc = snes.getKSP().getPC()
        # Its own prefix: SNES VI resets the reduced KSP from the options at
        # every change of the inactive set; -<prefix>pc_type names the inner
        # preconditioner.
        pc.setOptionsPrefix(prefix + "inactive_")
        set_default_option(prefix + "inactive_pc_type", "python")
        pc.setType(PETSc.PC.Type.PYTHON)
        pc.setPythonContext(self)
        # P's block size and near-nullspace come with the duplicate, its
        # fields with set_fields; GAMG reuses its prolongators (solver.py).
        self.P_D = P.duplicate(copy=True)
        modes = P.getNearNullSpace()
        if modes is not None and modes.handle:
            self.P_D.setNearNullSpace(modes)
        self.inner = PETSc.PC().create(P.getComm())
        self.inner.setOptionsPrefix(prefix)
        self.inner.setOperators(self.P_D, self.P_D)
        self.inner.setFromOptions()
        set_fields(self.inner, fields, prefix)
        self.r_full, self.y_full = P.createVecs()
        self.inactive = None

    def setUp(self, pc):
        start = time.perf_counter()
        # The inactive set of this Newton step, kept as local indices: the
        # set-up is reused for as long as the set is unchanged.
        inactive = self.snes.getVIInactiveSet()
        first, last = self.P.getOwnershipRange()
        self.inactive = inactive.getIndices() - first
        active = np.setdiff1d(np.arange(first, last, dtype=PETSc.IntType), inactive.getIndices())
        self.P.copy(self.P_D, structure=PETSc.Mat.Structure.SAME_NONZERO_PATTERN)
        if self.row_weights is not None:
            self.P_D.diagonalScale(L=self.row_weights)
        self.P_D.zeroRowsColumns(active, diag=1.0)
        self.inner.setOperators(self.P_D, self.P_D)
        self.inner.setUp()
        self.setups += 1
        self.setup_time += time.perf_counter() - start

    def apply(self, pc, r, y):
        # y_I = R_I B(P_D)^-1 R_I^T r_I; the active entries of r are zero.
        self.r_full.set(0.0)
        self.r_full.getArray()[self.inactive] = r.getArray(readonly=True)
        self.inner.apply(self.r_full, self.y_full)
        y.getArray()[:] = self.y_full.getArray(readonly=True)[self.inactive]
