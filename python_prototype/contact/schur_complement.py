"""Static condensation of A x = b onto the contact DOFs C
(cpp/contact/schur_complement.h; docs/theory.md, "Solvers").

With I the other DOFs, x_I = A_II^{-1} (b_I - A_IC y) for x_C = y, and the
residual on C of that x is H y - g with the Schur complement
H = A_CC - A_CI A_II^{-1} A_IC and the condensed load
g = b_C - A_CI A_II^{-1} b_I: the bound-constrained problem on (H, g) has the
solution y = x_C of the one on (A, b). How H is formed and shared:
SchurComplement."""
import time

import numpy as np
from mpi4py import MPI
from petsc4py import PETSc

from ..solvers.linear_solver import LinearSolver


class SchurComplement:
    """The Schur complement H of A on the contact DOFs, and the solves
    around it. A_II^{-1} is applied through one factorisation of A_C (the
    contact rows and columns made identity), valid for every inactive set;
    H is formed once per operator from m back-solves and kept dense on every
    rank.

    When each rank holds a copy of the factorisation (one rank, or
    PCREDUNDANT on several), A and A_C are gathered whole on every rank and
    factorised there with the factorisation's options (<prefix>redundant_ on
    several ranks); each rank forms its share of H's columns (m / ranks) and
    the ranks exchange them. Otherwise (MUMPS across the ranks) every column
    is a distributed back-solve."""

    def __init__(self, comm, prefix, A, structure, dofs):
        self.comm, self.prefix, self.A, self.structure = comm, prefix, A, structure
        self.dofs = np.asarray(dofs, dtype=np.int32)
        self.counts = np.array(comm.allgather(len(self.dofs)), dtype=np.int64)
        self.displacements = np.concatenate([[0], np.cumsum(self.counts)[:-1]]).astype(np.int64)
        self.offset, self.m = int(self.displacements[comm.rank]), int(self.counts.sum())
        self.first_row = A.getOwnershipRange()[0]
        own = (self.first_row + self.dofs).astype(PETSc.IntType)
        # each rank solves with the whole matrix: one rank, or PCREDUNDANT
        self.whole = comm.size == 1 or PETSc.Options().getString(prefix + "pc_type", "") == "redundant"
        # the contact rows of H's column solves, in H's order: all of them or this rank's
        self.rows = np.concatenate(comm.allgather(own)).astype(PETSc.IntType) if self.whole else own
        self.A_whole, self.to_all = None, None
        self.v, self.w = A.createVecs()
        if self.whole and comm.size > 1:
            self.to_all, self.b_whole = PETSc.Scatter.toAll(self.w)
            self.x_whole = self.b_whole.duplicate()
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

    def _contact_values(self, at_contact):
        """Values at the contact rows of a column solve's vectors, in H's
        order, on every rank (all of them, or gathered from each rank's own)."""
        return np.array(at_contact) if self.whole else self.gather(at_contact)

    def _matrix(self):
        """The matrix this rank solves with and multiplies by: A, or A gathered."""
        return self.A_whole if self.A_whole is not None else self.A

    def _local(self):
        """Where a column solve's vectors hold `rows`."""
        return self.rows - (0 if self.A_whole is not None else self.first_row)

    def _column_of(self):
        """The column of H of each of `rows`."""
        return np.arange(self.m) if self.whole else self.offset + np.arange(len(self.dofs))

    def _solve(self, x, b):
        """A_C x = b for x and b of A's layout, with the whole copy when each
        rank holds one (the right-hand side gathered, each rank keeping its
        part of the solution, as PCREDUNDANT does)."""
        if self.A_whole is None:
            self.solver.solve(x, b)
            return
        self.to_all.scatter(b, self.b_whole, PETSc.InsertMode.INSERT_VALUES, PETSc.ScatterMode.FORWARD)
        self.solver.solve(self.x_whole, self.b_whole)
        lo, hi = x.getOwnershipRange()
        with x as own:
            own[:] = self.x_whole.getArray(readonly=True)[lo:hi]

    def assemble(self):
        """Factorises A_C (on each rank's whole copy when the system's
        factorisation is one) and forms H from the current values of A."""
        ranks, rank = self.comm.size, self.comm.rank
        if self.whole and ranks > 1:
            self.A_whole = self.A.getRedundantMatrix(ranks, PETSc.COMM_SELF)
        clamped = self._matrix().duplicate(copy=True)
        clamped.zeroRowsColumns(self.rows, 1.0)
        self.clamped = clamped
        prefix = self.prefix + "redundant_" if self.A_whole is not None else self.prefix
        self.solver = LinearSolver(clamped.getComm(), prefix, clamped, clamped, self.structure)
        self.solver.set_up()
        start = time.perf_counter()
        n = self.A.getSize()[0]
        block = int(np.clip(int(4e6 / max(n, 1)), 1, 64))
        share = [self.m * r // ranks for r in range(ranks + 1)]  # each rank's columns, when whole
        begin, end = (share[rank], share[rank + 1]) if self.whole else (0, self.m)
        H = self.H.getDenseArray()  # the local (= whole) array, column-major underneath
        for first in range(begin, end, block):
            count = min(block, end - first)
            H[:, first:first + count] = self._columns(first, count)
        if self.A_whole is not None:  # each rank's columns to every rank
            for r in range(ranks):
                H[:, share[r]:share[r + 1]] = self.comm.bcast(H[:, share[r]:share[r + 1]], root=r)
        self.H.assemble()
        self.columns += self.m
        self.time += time.perf_counter() - start

    def _columns(self, first, count):
        """Columns first..first+count of H: (A E_j)_C with E_j = e_j -
        A_C^{-1} (A e_j)|_I, the unit displacement of contact DOF j extended
        to I with the other contact DOFs held at zero."""
        S = self._matrix()
        E = PETSc.Mat().createDense(((S.getLocalSize()[0], None), (None, count)), comm=S.getComm())
        E.setUp()
        for row, j in zip(self.rows, self._column_of()):
            if first <= j < first + count:
                E.setValue(row, j - first, 1.0)
        E.assemble()
        R = S.matMult(E)
        R.getDenseArray()[self._local(), :] = 0.0  # (A e_j) with the rows of C zeroed
        X = R.duplicate()
        self.solver.solve_block(X, R)  # vanishes on C
        E.axpy(-1.0, X)
        AE = S.matMult(E)
        at_contact = AE.getDenseArray()[self._local(), :]
        result = np.column_stack([self._contact_values(at_contact[:, c]) for c in range(count)]) if count else None
        for M in (E, R, X, AE):
            M.destroy()
        return result

    def condensed_load(self, b):
        """g = b_C - A_CI A_II^{-1} b_I on every rank (one back-solve)."""
        b.copy(self.w)
        with self.w as w:
            w[self.dofs] = 0.0
        self._solve(self.v, self.w)
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
        self._solve(x, self.w)
