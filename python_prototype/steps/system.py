"""One system of a step (cpp/steps/system.h): the matrix of a bilinear form and
what answers it, a linear solve or, with contact, the bound-constrained
problem on it. How it is solved is decided here and in solvers/solver.py."""
import time

from ..assembly.linear_algebra import assemble_matrix, reassemble_matrix
from ..assembly.tied_dofs import TiedDofs
from ..contact.contact import ContactOperators, ContactSolver, ContactUnknowns
from ..solvers.field_split import is_coupled
from ..solvers.solver import (LinearSolver, Method, SolverStage, SolverStatistics, SystemLayout, choose_method,
                              set_solver_defaults, solver_counts)


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

    def operator_matrix(self):
        """The matrix that is solved: A, or A' of the ties."""
        return self.A_tied if self.A_tied is not None else self.A

    def preconditioner_matrix(self):
        """The operator, or the matrix of a_preconditioner on the iterative
        path (tied too)."""
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

    def use_contact(self, contact_set, displacement_dofs):
        """Every solve becomes the contact problem of `contact_set`
        (`displacement_dofs` place V's owned DOFs in x)."""
        self.linear = None
        self.contact = ContactSolver(self.comm, SystemLayout(self.prefix, self.structure, self.fields), self.method,
                                     ContactOperators(self.operator_matrix(), self.preconditioner_matrix()),
                                     ContactUnknowns(contact_set, displacement_dofs))

    def has_contact(self):
        return self.contact is not None

    def begin_step(self, x):
        """A time step starts at x: friction's slip increments are measured
        from it (ContactSolver.set_slip_reference; nothing without contact)."""
        if self.contact:
            self.contact.set_slip_reference(x)

    def solve(self, b, x):
        """Solves with x as the initial guess."""
        start = time.perf_counter()
        with self.stage:
            y = x
            if self.tied:  # solve for y, x = P y (assembly/tied_dofs.py)
                self.tied.load(b, self.b_tied)
                self.tied.guess(x, self.y_tied)
                b, y = self.b_tied, self.y_tied
            if self.contact:
                self.contact.solve(b, y)
            else:
                self._statistics.linear_iterations += self.linear.solve(y, b)
            if self.tied:
                self.tied.expand(y, x)
        self._statistics.total_time += time.perf_counter() - start
        self._statistics.solves += 1

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
        for name in solver_counts:
            setattr(s, name, getattr(s, name) + getattr(self._earlier, name))
        return s

    def description(self):
        from petsc4py import PETSc
        options = PETSc.Options()
        pc = options.getString(self.prefix + "pc_type", "")
        d = (f"SNES vinewtonrsls ({self.contact.method()}), " if self.contact else "") + options.getString(self.prefix + "ksp_type", "") \
            + " + " + pc
        # PCREDUNDANT: the factorisation each rank holds a copy of
        factor = self.prefix + "redundant_" if pc == "redundant" else self.prefix
        factor_pc = options.getString(factor + "pc_type", "")
        package = options.getString(factor + "pc_factor_mat_solver_type", "")
        if package and factor_pc in ("lu", "cholesky"):
            d += f" ({factor_pc}, {package} on each rank)" if pc == "redundant" else f" ({package})"
        return d
