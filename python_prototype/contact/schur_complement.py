"""Static condensation of A x = b onto the contact DOFs C
(cpp/contact/schur_complement.h).

With I the other DOFs, x_I = A_II^{-1} (b_I - A_IC y) for x_C = y, and the
residual on C of that x is H y - g with the Schur complement
H = A_CC - A_CI A_II^{-1} A_IC and the condensed load
g = b_C - A_CI A_II^{-1} b_I: the bound-constrained problem on (H, g) has the
solution y = x_C of the one on (A, b). A_II^{-1} is applied through one
factorisation of A_C (the contact rows and columns made identity), valid for
every inactive set; H is formed once per operator from m back-solves and kept
dense on every rank."""
import time

import numpy as np
from mpi4py import MPI
from petsc4py import PETSc

from ..solvers.solver import LinearSolver


class SchurComplement:
    def __init__(self, comm, prefix, A, structure, dofs):
        self.comm, self.prefix, self.A, self.structure = comm, prefix, A, structure
        self.dofs = np.asarray(dofs, dtype=np.int32)
        self.counts = np.array(comm.allgather(len(self.dofs)), dtype=np.int64)
        self.displacements = np.concatenate([[0], np.cumsum(self.counts)[:-1]]).astype(np.int64)
        self.offset, self.m = int(self.displacements[comm.rank]), int(self.counts.sum())
        self.first_row = A.getOwnershipRange()[0]
        self.v, self.w = A.createVecs()
        self.H = PETSc.Mat().createDense((self.m, self.m), comm=PETSc.COMM_SELF)
        self.H.setUp()
        self.solver = None
        self.columns, self.time = 0, 0.0

    def size(self):
        return self.m

    def gather(self, local):
        """all[offset + k] = local[k] from every rank (collective)."""
        result = np.empty(self.m)
        self.comm.Allgatherv(np.ascontiguousarray(local, dtype=np.float64),
                             [result, self.counts, self.displacements, MPI.DOUBLE])
        return result

    def assemble(self):
        """Factorises A_C and forms H from the current values of A."""
        clamped = self.A.duplicate(copy=True)
        clamped.zeroRowsColumns((self.first_row + self.dofs).astype(PETSc.IntType), 1.0)
        self.clamped = clamped
        self.solver = LinearSolver(self.comm, self.prefix, clamped, clamped, self.structure)
        self.solver.set_up()
        start = time.perf_counter()
        n = self.A.getSize()[0]
        block = int(np.clip(int(4e6 / max(n, 1)), 1, 64))
        H = self.H.getDenseArray()  # the local (= whole) array, column-major underneath
        for first in range(0, self.m, block):
            count = min(block, self.m - first)
            H[:, first:first + count] = self._columns(first, count)
        self.H.assemble()
        self.columns += self.m
        self.time += time.perf_counter() - start

    def _columns(self, first, count):
        """Columns first..first+count of H: (A E_j)_C with E_j = e_j -
        A_C^{-1} (A e_j)|_I, the unit displacement of contact DOF j extended
        to I with the other contact DOFs held at zero."""
        n_local = self.A.getLocalSize()[0]
        E = PETSc.Mat().createDense(((n_local, None), (None, count)), comm=self.comm)
        E.setUp()
        for k, dof in enumerate(self.dofs):
            j = self.offset + k
            if first <= j < first + count:
                E.setValue(self.first_row + dof, j - first, 1.0)
        E.assemble()
        R = self.A.matMult(E)
        R.getDenseArray()[self.dofs, :] = 0.0  # (A e_j) with the rows of C zeroed
        X = R.duplicate()
        self.solver.solve_block(X, R)  # vanishes on C
        E.axpy(-1.0, X)
        AE = self.A.matMult(E)
        local = AE.getDenseArray()[self.dofs, :]
        result = np.column_stack([self.gather(local[:, c]) for c in range(count)]) if count else None
        for M in (E, R, X, AE):
            M.destroy()
        return result

    def condensed_load(self, b):
        """g = b_C - A_CI A_II^{-1} b_I on every rank (one back-solve)."""
        b.copy(self.w)
        with self.w as w:
            w[self.dofs] = 0.0
        self.solver.solve(self.v, self.w)
        self.A.mult(self.v, self.w)
        return self.gather(b.getArray(readonly=True)[self.dofs] - self.w.getArray(readonly=True)[self.dofs])

    def restrict_to_contact(self, x):
        """y = x_C on every rank."""
        return self.gather(x.getArray(readonly=True)[self.dofs])

    def extend(self, b, y, x):
        """x with x_C = y and x_I = A_II^{-1} (b_I - A_IC y) (one back-solve):
        A_C x = r with r = b - A y (y embedded by zeros) and r_C = y."""
        mine = y[self.offset:self.offset + len(self.dofs)]
        self.v.set(0.0)
        with self.v as v:
            v[self.dofs] = mine
        self.A.mult(self.v, self.w)
        self.w.aypx(-1.0, b)
        with self.w as w:
            w[self.dofs] = mine
        self.solver.solve(x, self.w)
