"""Algebraic multigrid for the Newton steps of the contact VI on the full
system (cpp/inactive_set_preconditioner.h, which explains the mathematics).

SNES VI's reduced matrix A_II loses A's block size and near-nullspace; this
preconditioner applies AMG to A_D, A with the active rows and columns made
identity rows, which keeps both, and (A_D)^-1 restricted to the inactive set
I is A_II^-1:  P^-1 r_I = R_I AMG(A_D)^-1 R_I^T r_I."""
import time

import numpy as np
from petsc4py import PETSc

from .solver import set_default_option


class InactiveSetPreconditioner:
    def __init__(self, snes, A, prefix):
        self.snes, self.A = snes, A
        self.setups, self.setup_time = 0, 0.0
        pc = snes.getKSP().getPC()
        # Its own prefix: SNES VI resets the reduced KSP from the options at
        # every change of the inactive set; -<prefix>pc_type names the AMG.
        pc.setOptionsPrefix(prefix + "inactive_")
        set_default_option(prefix + "inactive_pc_type", "python")
        pc.setType(PETSc.PC.Type.PYTHON)
        pc.setPythonContext(self)
        set_default_option(prefix + "pc_gamg_reuse_interpolation", "true")
        self.A_D = A.duplicate(copy=True)
        modes = A.getNearNullSpace()
        if modes is not None and modes.handle:
            self.A_D.setNearNullSpace(modes)
        self.amg = PETSc.PC().create(A.getComm())
        self.amg.setOptionsPrefix(prefix)
        self.amg.setOperators(self.A_D, self.A_D)
        self.amg.setFromOptions()
        self.r_full, self.y_full = A.createVecs()
        self.inactive = None

    def setUp(self, pc):
        start = time.perf_counter()
        # The inactive set of this Newton step, kept as local indices: the
        # set-up is reused for as long as the set is unchanged.
        inactive = self.snes.getVIInactiveSet()
        first, last = self.A.getOwnershipRange()
        self.inactive = inactive.getIndices() - first
        active = np.setdiff1d(np.arange(first, last, dtype=PETSc.IntType), inactive.getIndices())
        self.A.copy(self.A_D, structure=PETSc.Mat.Structure.SAME_NONZERO_PATTERN)
        self.A_D.zeroRowsColumns(active, diag=1.0)
        self.amg.setOperators(self.A_D, self.A_D)
        self.amg.setUp()
        self.setups += 1
        self.setup_time += time.perf_counter() - start

    def apply(self, pc, r, y):
        # y_I = R_I AMG(A_D)^-1 R_I^T r_I; the active entries of r are zero.
        self.r_full.set(0.0)
        self.r_full.getArray()[self.inactive] = r.getArray(readonly=True)
        self.amg.apply(self.r_full, self.y_full)
        y.getArray()[:] = self.y_full.getArray(readonly=True)[self.inactive]
