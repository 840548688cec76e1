#include "solvers/linear_solver.h"

#include "solvers/backward_error.h"

#include <cstdio>
#include <petscpc.h>

namespace biotcontact
{

namespace
{
/// check_petsc with "<the system> solver: <call>", the text built only when
/// the call failed (some calls run once per back-solve or column).
void check_solver(PetscErrorCode code, const std::string& prefix, const char* call)
{
  if (code != 0)
    check_petsc(code, system_name(prefix) + " solver: " + call);
}

/// The PC that factorises: PCREDUNDANT's inner one when each rank holds a
/// copy of the matrix, else the KSP's own.
PC factor_pc(KSP ksp)
{
  PC pc;
  check_petsc(KSPGetPC(ksp, &pc), "a factorisation: KSPGetPC");
  PetscBool redundant = PETSC_FALSE;
  check_petsc(PetscObjectTypeCompare(reinterpret_cast<PetscObject>(pc), PCREDUNDANT, &redundant),
              "a factorisation: PetscObjectTypeCompare");
  if (redundant)
  {
    KSP inner;
    check_petsc(PCRedundantGetKSP(pc, &inner), "a factorisation: PCRedundantGetKSP");
    check_petsc(KSPGetPC(inner, &pc), "a factorisation: KSPGetPC of PCREDUNDANT's solver");
  }
  return pc;
}

/// The factorisation package of a KSP ("" when it does not factorise).
std::string factor_package(KSP ksp)
{
  MatSolverType package = nullptr;
  check_petsc(PCFactorGetMatSolverType(factor_pc(ksp), &package), "a factorisation: PCFactorGetMatSolverType");
  return package ? package : "";
}

/// Whether a KSP factorises by LU (PCREDUNDANT's inner PC for it), which
/// another package may redo with pivoting: not ILU, PETSc's own only.
bool factorises_by_lu(KSP ksp)
{
  PetscBool lu = PETSC_FALSE;
  check_petsc(PetscObjectTypeCompare(reinterpret_cast<PetscObject>(factor_pc(ksp)), PCLU, &lu),
              "a factorisation: PetscObjectTypeCompare");
  return lu;
}

} // namespace

void set_relative_tolerance(KSP ksp, const std::string& prefix, double tolerance)
{
  PetscBool given = PETSC_FALSE;
  check_solver(PetscOptionsHasName(nullptr, prefix.c_str(), "-ksp_rtol", &given), prefix, "PetscOptionsHasName");
  if (!given)
    check_solver(KSPSetTolerances(ksp, tolerance, PETSC_DEFAULT, PETSC_DEFAULT, PETSC_DEFAULT), prefix,
                 "KSPSetTolerances");
}

LinearSolver::LinearSolver(MPI_Comm comm, const std::string& prefix, Mat A, Mat P, Structure structure,
                           const std::vector<Field>& fields)
    : _prefix(prefix)
{
  if (structure == Structure::spd)
    check_solver(MatSetOption(A, MAT_SPD, PETSC_TRUE), prefix, "MatSetOption MAT_SPD");
  check_solver(KSPCreate(comm, &_ksp), prefix, "KSPCreate");
  check_solver(KSPSetOptionsPrefix(_ksp, prefix.c_str()), prefix, "KSPSetOptionsPrefix");
  check_solver(KSPSetOperators(_ksp, A, P), prefix, "KSPSetOperators");
  // Bad input: the options given make no solver.
  if (const PetscErrorCode ierr = KSPSetFromOptions(_ksp); ierr != 0)
    throw OptionsError("the PETSc options of " + system_name(prefix) + " solver do not make a solver: "
                       + petsc_error_text(ierr));
  PC pc;
  check_solver(KSPGetPC(_ksp, &pc), prefix, "KSPGetPC");
  set_fields(pc, fields, prefix);
  // A Krylov method starts from x, the previous iterate (preonly refuses a
  // nonzero guess).
  PetscBool preonly = PETSC_TRUE;
  check_solver(PetscObjectTypeCompare(reinterpret_cast<PetscObject>(_ksp), KSPPREONLY, &preonly), prefix,
               "PetscObjectTypeCompare");
  _direct = preonly;
  // A package the user named is held to a backward error: pivoting by
  // magnitude alone (KLU, serial SuperLU without equilibration) solved
  // conduit_transient's flow system wrongly (p 4e5 times off) and passed,
  // preonly having no test (docs/theory.md).
  _checked = preonly and given_by_user(factor_prefix(prefix) + "pc_factor_mat_solver_type");
  if (!preonly)
  {
    check_solver(KSPSetInitialGuessNonzero(_ksp, PETSC_TRUE), prefix, "KSPSetInitialGuessNonzero");
    set_relative_tolerance(_ksp, prefix, iterative_tolerance);
  }
}

LinearSolver::~LinearSolver() { warn_petsc(KSPDestroy(&_ksp), "a linear solver: KSPDestroy"); }

int LinearSolver::solve(Vec x, Vec b)
{
  run([&] { return KSPSolve(_ksp, b, x); });
  if (_checked)
    refine(x, b);
  PetscInt its = 0;
  check_solver(KSPGetIterationNumber(_ksp, &its), _prefix, "KSPGetIterationNumber");
  return static_cast<int>(its);
}

void LinearSolver::refine(Vec x, Vec b)
{
  Mat A;
  check_solver(KSPGetOperators(_ksp, &A, nullptr), _prefix, "KSPGetOperators");
  Vec r, dx;
  check_solver(VecDuplicate(b, &r), _prefix, "VecDuplicate");
  check_solver(VecDuplicate(x, &dx), _prefix, "VecDuplicate");
  double error = backward_error(A, x, b, r);
  for (int step = 0; step < refinement_steps and !(error <= backward_error_tolerance); ++step)
  {
    run([&] { return KSPSolve(_ksp, r, dx); });
    check_solver(VecAXPY(x, 1.0, dx), _prefix, "VecAXPY");
    error = backward_error(A, x, b, r);
  }
  check_solver(VecDestroy(&r), _prefix, "VecDestroy");
  check_solver(VecDestroy(&dx), _prefix, "VecDestroy");
  if (!(error <= backward_error_tolerance))
  {
    char text[16];
    std::snprintf(text, sizeof text, "%.2g", error);
    throw SolverError(system_name(_prefix) + " linear solver failed: the factorisation by " + factor_package(_ksp)
                      + " solved with a componentwise backward error of " + text + " after "
                      + std::to_string(refinement_steps) + " steps of iterative refinement (the default "
                      + "package needs no option)");
  }
}

void LinearSolver::set_up()
{
  run([] { return PetscErrorCode(0); });
}

void LinearSolver::solve(Mat X, Mat B)
{
  if (factor_package(_ksp) != MATSOLVERSUPERLU_DIST)
  {
    run([&] { return KSPMatSolve(_ksp, B, X); });
    return;
  }
  // PETSc 3.18's SuperLU_DIST solves a block of right-hand sides with the
  // solve structure of the first block's width, and aborts ("double free
  // or corruption") on a later block of another width (the last block of
  // the Schur complement's columns, measured on 2 ranks at [160,16]): one
  // column at a time.
  PetscInt columns = 0;
  check_solver(MatGetSize(B, nullptr, &columns), _prefix, "MatGetSize of the right-hand sides");
  for (PetscInt j = 0; j < columns; ++j)
  {
    Vec b, x;
    check_solver(MatDenseGetColumnVecRead(B, j, &b), _prefix, "MatDenseGetColumnVecRead");
    check_solver(MatDenseGetColumnVecWrite(X, j, &x), _prefix, "MatDenseGetColumnVecWrite");
    run([&] { return KSPSolve(_ksp, b, x); });
    check_solver(MatDenseRestoreColumnVecWrite(X, j, &x), _prefix, "MatDenseRestoreColumnVecWrite");
    check_solver(MatDenseRestoreColumnVecRead(B, j, &b), _prefix, "MatDenseRestoreColumnVecRead");
  }
}

bool LinearSolver::solve_nearby(const std::function<PetscErrorCode()>& solve)
{
  // A change of a few rows is a low-rank change: GMRES preconditioned by
  // the old factors converges in about as many iterations as the rank.
  check_solver(KSPSetReusePreconditioner(_ksp, PETSC_TRUE), _prefix, "KSPSetReusePreconditioner");
  check_solver(KSPSetType(_ksp, KSPGMRES), _prefix, "KSPSetType");
  check_solver(KSPSetTolerances(_ksp, nearby_tolerance, 0.0, PETSC_DEFAULT, nearby_iterations), _prefix,
               "KSPSetTolerances");
  const PetscErrorCode ierr = agreed_code(solve(), PetscObjectComm(reinterpret_cast<PetscObject>(_ksp))); // one path
  KSPConvergedReason reason = KSP_CONVERGED_ITERATING;
  check_solver(KSPGetConvergedReason(_ksp, &reason), _prefix, "KSPGetConvergedReason");
  check_solver(KSPSetType(_ksp, KSPPREONLY), _prefix, "KSPSetType");
  check_solver(KSPSetReusePreconditioner(_ksp, PETSC_FALSE), _prefix, "KSPSetReusePreconditioner");
  _stale = ierr == 0 and reason > 0;
  _operator_changed = !_stale;
  return _stale;
}

void LinearSolver::run(const std::function<PetscErrorCode()>& solve)
{
  if (_stale and solve_nearby(solve))
    return;
  // Set-up first, so that the log keeps factorisation (PCSetUp) and
  // back-solve (KSPSolve) apart; a no-op while the operator is unchanged.
  const bool set_up = _operator_changed;
  _operator_changed = false;
  PetscErrorCode ierr = set_up_and_solve(solve, set_up);
  KSPConvergedReason reason = KSP_CONVERGED_ITERATING;
  check_solver(KSPGetConvergedReason(_ksp, &reason), _prefix, "KSPGetConvergedReason");
  // A quasi-definite matrix whose negative block is at round-off against
  // the rest (tiny S + L) can still meet a tiny pivot without pivoting:
  // factorise it once more with UMFPACK, which pivots (one rank, as PETSc's
  // LU, each rank on its copy when there are several; its solve phase costs
  // a tenth of MUMPS's on the fracture scene's flow system, 1.4e4
  // unknowns); and where UMFPACK fails too (out of memory: its 32-bit
  // workspace, the flow system of fault_reactivation refined three times,
  // 7.6e5 unknowns), with MUMPS.
  using Retry = std::pair<const char*, const char*>; // a failed package, the next one
  for (const auto& [failed, next] : {Retry{MATSOLVERPETSC, MATSOLVERUMFPACK}, Retry{MATSOLVERUMFPACK, MATSOLVERMUMPS}})
    if ((ierr != 0 or reason == KSP_DIVERGED_PC_FAILED) and factor_package(_ksp) == failed and factorises_by_lu(_ksp))
      ierr = refactorise(next, solve, reason);
  if (ierr != 0)
    throw SolverError(system_name(_prefix) + " linear solver failed: " + petsc_error_text(ierr));
  if (reason < 0)
    throw SolverError(system_name(_prefix) + " linear solver failed: " + KSPConvergedReasons[reason]);
}

PetscErrorCode LinearSolver::refactorise(const char* package, const std::function<PetscErrorCode()>& solve,
                                         KSPConvergedReason& reason)
{
  const char* at = nullptr;
  check_solver(PCGetOptionsPrefix(factor_pc(_ksp), &at), _prefix, "PCGetOptionsPrefix");
  const std::string factor = at ? at : _prefix;
  check_solver(PetscOptionsSetValue(nullptr, ("-" + factor + "pc_factor_mat_solver_type").c_str(), package), _prefix,
               "PetscOptionsSetValue");
  // The PC keeps the nested-dissection ordering of the first attempt
  // unless told otherwise; given one, UMFPACK uses it instead of its own
  // (6x slower solves here).
  const std::string ordering = "-" + factor + "pc_factor_mat_ordering_type";
  check_solver(PetscOptionsSetValue(nullptr, ordering.c_str(), MATORDERINGEXTERNAL), _prefix, "PetscOptionsSetValue");
  Mat A, P; // owned by the system: they outlive the reset
  check_solver(KSPGetOperators(_ksp, &A, &P), _prefix, "KSPGetOperators");
  check_solver(KSPReset(_ksp), _prefix, "KSPReset");
  // PCREDUNDANT keeps its inner solver's failure past a reset.
  PC pc;
  check_solver(KSPGetPC(_ksp, &pc), _prefix, "KSPGetPC");
  check_solver(PCSetFailedReason(pc, PC_NOERROR), _prefix, "PCSetFailedReason");
  check_solver(PCSetFailedReason(factor_pc(_ksp), PC_NOERROR), _prefix, "PCSetFailedReason");
  check_solver(KSPSetOperators(_ksp, A, P), _prefix, "KSPSetOperators");
  check_solver(KSPSetFromOptions(_ksp), _prefix, "KSPSetFromOptions");
  const PetscErrorCode ierr = set_up_and_solve(solve, false);
  check_solver(KSPGetConvergedReason(_ksp, &reason), _prefix, "KSPGetConvergedReason");
  return ierr;
}

PetscErrorCode LinearSolver::set_up_and_solve(const std::function<PetscErrorCode()>& solve, bool counted)
{
  const double start = MPI_Wtime();
  auto count = [&]
  {
    if (counted)
      ++setups, setup_time += MPI_Wtime() - start;
  };
  // A failed set-up (a zero pivot) is returned, not thrown: run() retries
  // it with another package. A failure may be one rank's (PCREDUNDANT
  // factorises a copy on each): the ranks agree on it before going on.
  const MPI_Comm comm = PetscObjectComm(reinterpret_cast<PetscObject>(_ksp));
  const PetscErrorCode ierr = agreed_code(KSPSetUp(_ksp), comm);
  count();
  return ierr != 0 ? ierr : agreed_code(solve(), comm);
}

} // namespace biotcontact
