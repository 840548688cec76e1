"""One system of a step (cpp/steps/system.h): the matrix of a bilinear form and
what answers it, a linear solve or, with contact, the bound-constrained
problem on it. How it is solved is decided here and in solvers/solver.py."""
import dataclasses
import time

import numpy as np
from mpi4py import MPI
from petsc4py import PETSc

from ..assembly.linear_algebra import assemble_matrix, reassemble_matrix
from ..assembly.tied_dofs import TiedDofs
from ..contact.contact import ContactOperators, ContactSolver, ContactUnknowns
from ..solvers.block_matrix import BlockMatrix
from ..solvers.field_split import Field, block_offset, is_coupled
from ..solvers.linear_solver import LinearSolver
from ..solvers.solver import Method, SystemLayout, choose_method, factor_prefix, set_solver_defaults
from ..solvers.solver_statistics import SolverStage, SolverStatistics, solver_counts


@dataclasses.dataclass
class AppendedUnknowns:
    """Unknowns y appended after a system's own (the conduit faults'
    pressure, assembly/fault_flow.py), each rank's after its rows of x:
    [[A + D, E], [B, C]] [x; y] = [b; b_y], D a diagonal on A's rows, E =
    B^T (the flow step's symmetric system) unless given (the monolithic
    step's, where y also loads the displacement's rows and B holds the rate
    of the faults' opening)."""
    B: PETSc.Mat
    C: PETSc.Mat
    diagonal: list           # (global row of A, value) on the rank that owns the row
    b: np.ndarray = None     # b_y (this rank's entries), set before each solve
    x: np.ndarray = None     # y: the guess of each solve, then its solution
    E: PETSc.Mat = None      # A's rows against y; None: B^T
    # Added to C's diagonal in the preconditioner's matrix only (this rank's
    # entries; the iterative path): the fixed-stress term of y's rows.
    preconditioner_diagonal: np.ndarray = None


def _copy_in(x, appended, whole):
    """Copies x then `appended` into `whole`, a vector of the appended system."""
    n = x.getLocalSize()
    whole.array[:n], whole.array[n:] = x.array_r, appended


@dataclasses.dataclass
class _FilledFrom:
    """The block `a` an appended operator was last filled from, and the
    operator's version (reassemblies) then."""
    a: object = None
    version: int = -1


class System:
    """`layout` (a SystemLayout) names the system's PETSc options and its
    log stage and gives the (name, global DOFs) splits of a mixed system;
    `choice` is the scene's [solver] entry (a SolverChoice)."""

    def __init__(self, comm, a, bcs, layout, choice, a_preconditioner=None):
        """`a_preconditioner` (optional): the form an iterative method builds
        its preconditioner from instead of `a` (the fixed-stress matrix of
        the coupled system)."""
        prefix, structure = layout.prefix, layout.structure
        self.comm, self.prefix, self.a, self.bcs, self.structure = comm, prefix, a, bcs, structure
        self.fields = list(layout.fields)
        self._statistics = SolverStatistics()
        start = time.perf_counter()
        self.A = assemble_matrix(a, bcs)
        self._statistics.assembly_time += time.perf_counter() - start
        self.stage = SolverStage(prefix[:-1])
        dimension = a.mesh.topology.dim
        self.method, self.method_reason = set_solver_defaults(
            prefix, structure, choose_method(choice, structure, self.unknowns(), dimension, comm.size,
                                             is_coupled(self.fields)), comm, self.fields)
        # a factorisation is of A itself; only a preconditioner takes another matrix
        self.a_preconditioner, self.P = None, None
        if a_preconditioner is not None and self.method == Method.iterative:
            start = time.perf_counter()
            self.a_preconditioner, self.P = a_preconditioner, assemble_matrix(a_preconditioner, bcs)
            self._statistics.assembly_time += time.perf_counter() - start
        self.contact = None
        self.tied, self.A_tied, self.P_tied = None, None, None
        self.appended, self.A_appended, self.P_appended = None, None, None
        self.A_filled, self.P_filled = _FilledFrom(), _FilledFrom()  # what A_appended, P_appended hold of A (P)
        self.version = 0  # reassemblies of A and P
        self._earlier = SolverStatistics()  # the counts of the run a restart continues
        # made now, so that options that make no solver are refused before the run
        self.linear = LinearSolver(comm, prefix, self.A, self.preconditioner_matrix(), structure, self.fields)

    def tie(self, ties):
        """Ties unknowns in pairs (x_j = s x_i, assembly/tied_dofs.py; the flux
        across a transparent fault): every later solve is of the tied
        system, its solution satisfying the ties (collective; nothing when
        no rank has a tie)."""
        if self.comm.allreduce(len(ties)) == 0:  # a scene without transparent faults builds nothing
            return
        self.tied = tied = TiedDofs(self.A, ties)
        self.A_tied = tied.reduce(self.A)
        if self.P is not None:
            self.P_tied = tied.reduce(self.P)
        modes = self.A.getNearNullSpace()
        if modes is not None and modes.handle:
            self.A_tied.setNearNullSpace(modes)
        self.y_tied, self.b_tied = self.A_tied.createVecs()
        self.linear = LinearSolver(self.comm, self.prefix, self.operator_matrix(), self.preconditioner_matrix(),
                                   self.structure, self.fields)

    def append(self, appended):
        """Solves with the AppendedUnknowns from now on (or, called again,
        with their new B, C and diagonal: same structure; collective). The
        appended unknowns join the "pressure" field of an iterative solve
        (of the coupled system: its "flow" field and, inside it,
        "pressure"), whose preconditioner's matrix is built alike from the
        fixed-stress matrix, C plus preconditioner_diagonal."""
        first = self.appended is None
        self.appended = appended
        big = self._appended_operator(self.A_tied if self.A_tied is not None else self.A, None,
                                      None if first else self.A_appended, self.A_filled)
        # The fixed-stress preconditioner's matrix gets the same rows, its own
        # fixed-stress term on C's diagonal.
        big_P = None if self.P is None else self._appended_operator(
            self.P_tied if self.P_tied is not None else self.P, appended.preconditioner_diagonal,
            None if first else self.P_appended, self.P_filled)
        if not first:
            if self.contact:
                self.contact.operator_nudged()
            else:
                self.linear.operator_nudged()
            return
        if self.contact:
            raise RuntimeError(f"{self.prefix}: unknowns appended after the contact (append before use_contact)")
        self.A_appended, self.P_appended = big, big_P
        self.x_appended, self.b_appended = big.createVecs()
        self._append_to_fields(appended.C.getLocalSize()[0])
        self.linear = LinearSolver(self.comm, self.prefix, self.A_appended, self.preconditioner_matrix(),
                                   self.structure, self.fields)

    def _append_to_fields(self, rows):
        """Adds the appended rows to the fields of an iterative solve, whose
        rows on each rank move by those appended on the ranks before: the
        nest's conversion numbers rank by rank, A's rows then C's (in the
        whole system's numbering and in a block's, the coupled system's
        "flow")."""
        shift = self.comm.exscan(rows) or 0  # None on rank 0
        start = self.A.getOwnershipRange()[0] + shift + self.A.getLocalSize()[0]  # this rank's first appended row
        appended = np.arange(start, start + rows, dtype=np.int64)
        fields = []
        for f in self.fields:
            dofs, splits = np.asarray(f.dofs) + shift, f.fields
            if f.name == "pressure":
                dofs = np.concatenate([dofs, appended])
            if f.name == "flow":  # the coupled system's, whose splits number its block
                block_start = block_offset(f, self.comm) + shift + len(f.dofs)
                dofs = np.concatenate([dofs, appended])
                splits = [Field(g.name, np.concatenate([np.asarray(g.dofs) + shift,
                                                        np.arange(block_start, block_start + rows)])
                                if g.name == "pressure" else np.asarray(g.dofs) + shift, g.block_size,
                                g.near_nullspace, g.fields)
                          for g in f.fields]
            fields.append(Field(f.name, dofs, f.block_size, f.near_nullspace, splits))
        self.fields = fields

    def _appended_operator(self, a, diagonal, into, filled):
        """[[a + D, B^T], [B, C + c]] as one AIJ matrix, `a` the operator or
        the preconditioner's matrix before the appended unknowns (tied, if
        so), c `diagonal` (none if None): its rows on each rank are a's, then
        C's (solvers/block_matrix.py). A new matrix, or `into` (the one made
        before, of the same structure) refilled: the conversion cost 18 ms a
        call on 2 ranks against 3 on 1 (docs/performance.md, thirty-fifth
        session); a's block only if a was reassembled since `filled`, which
        it updates (a changes with dt, B and C with the apertures)."""
        # D on any rank: a + D is made on every rank (the calls are
        # collective), also where a rank owns no row of D
        any_diagonal = self.comm.allreduce(bool(self.appended.diagonal), op=MPI.LOR)
        a_kept = into is not None and not any_diagonal and filled.a is a and filled.version == self.version
        filled.a, filled.version = (None, -1) if any_diagonal else (a, self.version)
        if any_diagonal:
            a = a.copy()
            for row, value in self.appended.diagonal:
                a.setValue(row, row, value, addv=True)
            a.assemble()
        B, E, C = self.appended.B, self.appended.E, self.appended.C
        E = B.transpose(PETSc.Mat()) if E is None else E
        if diagonal is not None:
            C, c = C.copy(), C.createVecs()[1]
            c.array[:] = diagonal
            C.setDiagonal(c, addv=PETSc.InsertMode.ADD_VALUES)
        layout = BlockMatrix(a, C)
        if into is None:
            return layout.convert(self.comm, [a, E, B, C])
        layout.refill(into, [None if a_kept else a, E, B, C])
        return into

    def whole(self, x, b):
        """The vectors [x; y] and [b; b_y] of the system with appended
        unknowns (x, b themselves without any): what the contact solver's
        state and active set read."""
        if self.appended is None:
            return x, b
        _copy_in(x, self.appended.x, self.x_appended)
        _copy_in(b, self.appended.b, self.b_appended)
        return self.x_appended, self.b_appended

    def operator_matrix(self):
        """The matrix that is solved: A, A' of the ties, or the system with
        appended unknowns."""
        if self.appended is not None:
            return self.A_appended
        return self.A_tied if self.A_tied is not None else self.A

    def preconditioner_matrix(self):
        """The operator, or the matrix of a_preconditioner on the iterative
        path (tied too, and with appended unknowns)."""
        if self.P_appended is not None:
            return self.P_appended
        if self.P is None:
            return self.operator_matrix()
        return self.P_tied if self.P_tied is not None else self.P

    def unknowns(self):
        return self.A.getSize()[0]

    def set_near_nullspace(self, modes):
        """The rigid-body modes, from which AMG builds its coarse spaces (the
        ties hold flux DOFs only)."""
        self.A.setNearNullSpace(modes)
        if self.A_tied is not None:
            self.A_tied.setNearNullSpace(modes)

    def use_contact(self, contact_set, displacement_dofs, balance_rows=(), once=False):
        """Every solve becomes the contact problem of `contact_set`
        (`displacement_dofs` place V's owned DOFs in x; `balance_rows` the
        local rows of x's mass balances, ContactUnknowns). Unknowns appended
        before are solved with it (their rows follow x's on each rank: V's
        DOFs keep their places), their rows among the mass balances.
        `once`: the run solves it once (ContactOperators.once)."""
        self.linear = None
        if self.appended is not None:
            rows = self.A.getLocalSize()[0]
            balance_rows = np.concatenate([np.asarray(balance_rows, dtype=np.int32),
                                           rows + np.arange(self.appended.C.getLocalSize()[0], dtype=np.int32)])
        operators = ContactOperators(self.operator_matrix(), self.preconditioner_matrix(), self.appended is not None,
                                     once)
        self.contact = ContactSolver(self.comm, SystemLayout(self.prefix, self.structure, self.fields), self.method,
                                     operators, ContactUnknowns(contact_set, displacement_dofs, balance_rows))

    def has_contact(self):
        return self.contact is not None

    def begin_step(self, x):
        """A time step starts at x: friction's slip increments are measured
        from it (ContactSolver.set_slip_reference; nothing without contact)."""
        if self.contact and self.appended is not None:
            _copy_in(x, self.appended.x, self.x_appended)
        if self.contact:
            self.contact.set_slip_reference(self.x_appended if self.appended is not None else x)

    def accept_step(self, x):
        """The step ending at x was accepted (ContactSolver.accept_step;
        nothing without contact)."""
        if self.contact and self.appended is not None:
            _copy_in(x, self.appended.x, self.x_appended)
        if self.contact:
            self.contact.accept_step(self.x_appended if self.appended is not None else x)

    def solve(self, b, x):
        """Solves with x as the initial guess."""
        start = time.perf_counter()
        with self.stage:
            y = x
            if self.tied:  # solve for y, x = P y (assembly/tied_dofs.py)
                self.tied.load(b, self.b_tied)
                self.tied.guess(x, self.y_tied)
                b, y = self.b_tied, self.y_tied
            if self.appended is not None:
                self._solve_appended(b, y)
            elif self.contact:
                self.contact.solve(b, y)
            else:
                self._statistics.linear_iterations += self.linear.solve(y, b)
            if self.tied:
                self.tied.expand(y, x)
        self._statistics.total_time += time.perf_counter() - start
        self._statistics.solves += 1

    def _solve_appended(self, b, x):
        """Solves the system with appended unknowns: [b; b_y] in, [x; y] out
        (by the contact solver if there is one)."""
        n, appended = b.getLocalSize(), self.appended
        _copy_in(b, appended.b, self.b_appended)
        _copy_in(x, appended.x, self.x_appended)
        if self.contact:
            self.contact.solve(self.b_appended, self.x_appended)
        else:
            self._statistics.linear_iterations += self.linear.solve(self.x_appended, self.b_appended)
        x.array[:] = self.x_appended.array_r[:n]
        appended.x[:] = self.x_appended.array_r[n:]

    def set_tolerance(self, relative):
        """The accuracy the coupling asks of the next solves (inexact
        coupling): iterative methods only; a factorisation is exact."""
        if self.method != Method.iterative:
            return
        if self.contact:
            self.contact.set_tolerance(relative)
        else:
            self.linear.set_tolerance(relative)

    def reassemble(self):
        """dt changed: the next solve factorises anew."""
        start = time.perf_counter()
        reassemble_matrix(self.A, self.a, self.bcs)
        self.version += 1
        if self.P is not None:
            reassemble_matrix(self.P, self.a_preconditioner, self.bcs)
        if self.tied:
            self.tied.reduce(self.A, self.A_tied)
        if self.tied and self.P is not None:
            self.tied.reduce(self.P, self.P_tied)
        self._statistics.assembly_time += time.perf_counter() - start
        if self.contact:
            self.contact.operator_changed()
        else:
            self.linear.operator_changed()

    def add_earlier(self, earlier):
        """The counts of the run a restart continues, added to statistics()."""
        self._earlier = earlier

    def newton_steps(self):
        """The contact solver's Newton steps so far in this run (0 without
        contact): what statistics() counts, without reading the log."""
        return self.contact.newton_iterations if self.has_contact() else 0

    def statistics(self):
        """The statistics of all solves so far, the counts of an earlier run
        included (restart)."""
        s = SolverStatistics()
        s.__dict__.update(self._statistics.__dict__)
        self.stage.read(s)
        # PCSetUp events count factorisations; an AMG hierarchy logs one per
        # level and smoother as well, so the solvers count their own set-ups
        # (and their times: PETSc's event times nest).
        if self.method == Method.iterative and not self.contact:
            s.setups, s.setup_time = self.linear.setups, self.linear.setup_time
        elif self.method == Method.iterative and self.contact.preconditioner_setups():
            s.setups, s.setup_time = self.contact.preconditioner_setups()
        if self.contact:
            s.newton_iterations = self.contact.newton_iterations
            s.linear_iterations = self.contact.linear_iterations
            s.active_set_changes = self.contact.active_set_changes
            s.schur_columns, s.schur_time = self.contact.schur_columns(), self.contact.schur_time()
            s.contact_factorizations = self.contact.contact_factorizations()
        for name in solver_counts:
            setattr(s, name, getattr(s, name) + getattr(self._earlier, name))
        return s

    def description(self):
        from petsc4py import PETSc
        options = PETSc.Options()
        pc = options.getString(self.prefix + "pc_type", "")
        # with the factorisation reused, the contact's Newton steps run GMRES
        # on it, not the system's own Krylov method
        krylov = "Newton steps by gmres on the last factorisation: " if self.contact and self.contact.reuses_factorization() \
            else options.getString(self.prefix + "ksp_type", "") + " + "
        d = (f"SNES vinewtonrsls ({self.contact.method()}), " if self.contact else "") + krylov + pc
        # PCREDUNDANT: the factorisation each rank holds a copy of
        factor = factor_prefix(self.prefix)
        factor_pc = options.getString(factor + "pc_type", "")
        package = options.getString(factor + "pc_factor_mat_solver_type", "")
        if package and factor_pc in ("lu", "cholesky"):
            d += f" ({factor_pc}, {package} on each rank)" if pc == "redundant" else f" ({package})"
            if package == "mumps" and options.getString(factor + "mat_mumps_icntl_7", "") == "0":
                d += ", analysis by AMD"  # contact/factorization_reuse.py
        return d
