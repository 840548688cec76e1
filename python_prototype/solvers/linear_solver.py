"""A linear system's solver (cpp/solvers/linear_solver.h): a KSP with the
options prefix of its system, set up anew only when the operator changes, a
factorisation reused for a nudged operator, another package tried where a
pivot fails, and a package the user names refined to a backward error
(backward_error). Its defaults come from set_solver_defaults (solver)."""
import time

from petsc4py import PETSc

from .backward_error import BACKWARD_ERROR_TOLERANCE, REFINEMENT_STEPS, backward_error
from .field_split import set_fields
from .options import OptionsError, system_name
from .solver import (ITERATIVE_TOLERANCE, SolverError, Structure, agreed_error, factor_prefix, given_by_user,
                     petsc_error_text, reason_name)


def _factorises_by_lu(ksp):
    """Whether a KSP factorises by LU (PCREDUNDANT's inner PC for it, read
    from the options as in factor_package), which another package may redo
    with pivoting: not ILU, PETSc's own only."""
    if ksp.getPC().getType() == PETSc.PC.Type.REDUNDANT:
        return PETSc.Options().getString(factor_prefix(ksp.getOptionsPrefix()) + "pc_type", "lu") == "lu"
    return ksp.getPC().getType() == PETSc.PC.Type.LU


def factor_package(ksp):
    """The factorisation package of a KSP ("" when it does not factorise;
    petsc4py 3.18 cannot reach PCREDUNDANT's inner PC, so its package is
    read from the options, where _set_direct_defaults put it)."""
    if ksp.getPC().getType() == PETSc.PC.Type.REDUNDANT:
        return PETSc.Options().getString(factor_prefix(ksp.getOptionsPrefix()) + "pc_factor_mat_solver_type", "petsc")
    return ksp.getPC().getFactorSolverType() or ""


def set_relative_tolerance(ksp, prefix, tolerance):
    """The relative tolerance of a Krylov method, unless -<prefix>ksp_rtol was
    given; on the KSP, not in the options database, which SNES VI re-reads at
    every change of the inactive set."""
    if not PETSc.Options().hasName(prefix + "ksp_rtol"):
        ksp.setTolerances(rtol=tolerance)


class LinearSolver:
    """KSP with an options prefix whose defaults set_solver_defaults set; set
    up anew only when the operator's values change; an iterative solve
    starts from the x it is given."""

    def __init__(self, comm, prefix, A, P, structure, fields=()):
        """Solves with A, preconditioned from P (A, or the fixed-stress
        matrix of the coupled system); `fields` are P's splits."""
        self.prefix = prefix
        self.setups, self.setup_time, self._operator_changed = 0, 0.0, True
        self._stale = False  # the factorisation is of an operator since nudged
        if structure == Structure.spd:
            A.setOption(PETSc.Mat.Option.SPD, True)
        self.ksp = PETSc.KSP().create(comm)
        self.ksp.setOptionsPrefix(prefix)
        self.ksp.setOperators(A, P)
        try:
            self.ksp.setFromOptions()
            set_fields(self.ksp.getPC(), fields, prefix)
            # A Krylov method starts from x, the previous iterate (preonly
            # refuses a nonzero guess).
            self._direct = self.ksp.getType() == PETSc.KSP.Type.PREONLY
            # A package the user named is held to a backward error: pivoting
            # by magnitude alone (KLU, serial SuperLU without equilibration)
            # solved conduit_transient's flow system wrongly and passed
            # (cpp/solvers/linear_solver.cpp).
            self._checked = self._direct and given_by_user(factor_prefix(prefix) + "pc_factor_mat_solver_type")
            if not self._direct:
                self.ksp.setInitialGuessNonzero(True)
                set_relative_tolerance(self.ksp, prefix, ITERATIVE_TOLERANCE)
        except PETSc.Error as e:  # e.g. -flow_pc_type ilu with a factorisation package
            raise OptionsError(f"the PETSc options of {system_name(prefix)} solver do not make a solver: "
                               f"{petsc_error_text(e)}") from None

    def set_tolerance(self, relative):
        """The relative tolerance of the next solves (a Krylov method only)."""
        set_relative_tolerance(self.ksp, self.prefix, relative)

    def operator_changed(self):
        """The operator's values changed: the next solve sets up (counted)."""
        self._operator_changed, self._stale = True, False

    # A nudged operator's solves: GMRES preconditioned by the stale factors,
    # to a tolerance above a back-solve's round-off (cpp/solvers/linear_solver.h)
    NEARBY_TOLERANCE, NEARBY_ITERATIONS = 1e-13, 10

    def operator_nudged(self):
        """The operator's values changed in a few rows (a fault's apertures):
        the solves that follow take the last factorisation as GMRES's
        preconditioner, to NEARBY_TOLERANCE, and factorise anew only when
        that does not converge in NEARBY_ITERATIONS (a direct method only)."""
        self._stale = self._stale or (self._direct and self.setups > 0 and not self._operator_changed)

    def _solve_nearby(self, solve):
        """`solve` by GMRES preconditioned by the stale factorisation (a
        change of a few rows is of low rank: about as many iterations as
        the rank): whether it converged (else the next solve factorises)."""
        self.ksp.getPC().setReusePreconditioner(True)  # KSPSetReusePreconditioner: petsc4py 3.18 has only the PC's
        self.ksp.setType(PETSc.KSP.Type.GMRES)
        self.ksp.setTolerances(rtol=self.NEARBY_TOLERANCE, atol=0.0, max_it=self.NEARBY_ITERATIONS)
        try:
            solve()
            error = None
        except PETSc.Error as e:
            error = e
        converged = agreed_error(error, self.ksp.getComm()) is None and self.ksp.getConvergedReason() > 0
        self.ksp.setType(PETSc.KSP.Type.PREONLY)
        self.ksp.getPC().setReusePreconditioner(False)
        self._stale, self._operator_changed = converged, not converged
        return converged

    def _run(self, solve):
        """Set-up first, so the log keeps factorisation and back-solve apart.
        The first error, agreed among the ranks (agreed_error: a failure may
        be one rank's, PCREDUNDANT factorising a copy on each); None."""
        start, error = time.perf_counter(), None
        try:
            self.ksp.setUp()
        except PETSc.Error as e:
            error = e
        if self._operator_changed:
            self.setups += 1
            self.setup_time += time.perf_counter() - start
            self._operator_changed = False
        if (error := agreed_error(error, self.ksp.getComm())) is not None:
            return error
        try:
            solve()
        except PETSc.Error as e:
            error = e
        return agreed_error(error, self.ksp.getComm())

    def solve(self, x, b):
        """Solves A x = b; the Krylov iterations. A package named on the
        command line is checked and refined (refine)."""
        iterations = self.run(lambda: self.ksp.solve(b, x))
        if self._checked:
            self.refine(x, b)
        return iterations

    def refine(self, x, b):
        """Iterative refinement of the solve x of A x = b by a package the
        user named until its backward error meets BACKWARD_ERROR_TOLERANCE;
        SolverError when REFINEMENT_STEPS do not reach it."""
        A = self.ksp.getOperators()[0]
        r, dx = b.duplicate(), x.duplicate()
        error = backward_error(A, x, b, r)
        for _ in range(REFINEMENT_STEPS):
            if error <= BACKWARD_ERROR_TOLERANCE:
                break
            self.run(lambda: self.ksp.solve(r, dx))
            x.axpy(1.0, dx)
            error = backward_error(A, x, b, r)
        r.destroy()
        dx.destroy()
        if not error <= BACKWARD_ERROR_TOLERANCE:
            raise SolverError(f"{system_name(self.prefix)} linear solver failed: the factorisation by "
                              f"{factor_package(self.ksp)} solved with a componentwise backward error of {error:.2g} "
                              f"after {REFINEMENT_STEPS} steps of iterative refinement (the default package needs "
                              "no option)")

    def set_up(self):
        """Factorises now, if the operator changed."""
        self.run(lambda: None)

    def solve_block(self, X, B):
        """A X = B for the columns of the dense B, one call into the
        factorisation (KSPMatSolve, which petsc4py 3.18 lacks: for preonly
        it is the preconditioner's PCMatApply, else a solve per column; per
        column with SuperLU_DIST too, whose block solve in PETSc 3.18 aborts
        on a block of another width than the first, cpp/solvers/linear_solver.cpp)."""
        def solve():
            if self.ksp.getType() == PETSc.KSP.Type.PREONLY and factor_package(self.ksp) != "superlu_dist":
                self.ksp.getPC().matApply(B, X)
                return
            for j in range(B.getSize()[1]):
                b, x = B.getColumnVector(j), X.getColumnVector(j)
                self.ksp.solve(b, x)
                X.getDenseArray()[:, j] = x.getArray(readonly=True)
        self.run(solve)

    def run(self, solve):
        if self._stale and self._solve_nearby(solve):
            return self.ksp.getIterationNumber()
        error = self._run(solve)
        # A quasi-definite matrix with a negative block at round-off can
        # still meet a tiny pivot: factorise once more with UMFPACK, which
        # pivots (one rank, as PETSc's LU, each rank on its copy when there
        # are several), and where UMFPACK fails too (out of memory: its
        # 32-bit workspace), with MUMPS (cpp/solvers/linear_solver.cpp).
        for failed, following in (("petsc", "umfpack"), ("umfpack", "mumps")):
            reason = self.ksp.getConvergedReason()
            if (error or reason == PETSc.KSP.ConvergedReason.DIVERGED_PCSETUP_FAILED) \
                    and factor_package(self.ksp) == failed and _factorises_by_lu(self.ksp):
                error = self._refactorise(following, solve)
        reason = self.ksp.getConvergedReason()
        if error:
            raise SolverError(f"{system_name(self.prefix)} linear solver failed: {petsc_error_text(error)}")
        if reason < 0:
            raise SolverError(f"{system_name(self.prefix)} linear solver failed: "
                              f"{reason_name(PETSc.KSP.ConvergedReason, reason)}")
        return self.ksp.getIterationNumber()

    def _refactorise(self, package, solve):
        """Factorises the operator again with `package` and runs `solve`."""
        factor = factor_prefix(self.prefix)
        options = PETSc.Options()
        options.setValue(factor + "pc_factor_mat_solver_type", package)
        # its own ordering, not the nested dissection the PC kept
        options.setValue(factor + "pc_factor_mat_ordering_type", "external")
        A, P = self.ksp.getOperators()
        comm = self.ksp.getComm()
        # A new KSP where C++ resets it and clears the failure that
        # PCREDUNDANT keeps past a reset (petsc4py 3.18 cannot clear it).
        self.ksp.destroy()
        self.ksp = PETSc.KSP().create(comm)
        self.ksp.setOptionsPrefix(self.prefix)
        self.ksp.setOperators(A, P)
        self.ksp.setFromOptions()
        return self._run(solve)
