#include "solver.h"

#include <functional>
#include <map>

namespace biotcontact
{

void set_default_option(const std::string& name, const std::string& value)
{
  PetscBool given = PETSC_FALSE;
  PetscOptionsHasName(nullptr, nullptr, ("-" + name).c_str(), &given);
  if (!given)
    PetscOptionsSetValue(nullptr, ("-" + name).c_str(), value.c_str());
}

void set_solver_defaults(const std::string& prefix, Structure structure, MPI_Comm comm)
{
  int ranks = 1;
  MPI_Comm_size(comm, &ranks);
  // The factorisation of each structure on one rank, as measured on the
  // default scene (docs/performance.md): MUMPS's solve phase costs 5-9
  // times a CHOLMOD or PETSc back-solve of the same matrix at 1e4-1e5
  // unknowns, and a run is thousands of back-solves. PETSc's LU does not
  // pivot, so it only takes quasi-definite matrices; neither runs on
  // several ranks.
  std::string pc = "lu", package = "mumps";
  if (ranks == 1 and structure == Structure::spd)
    pc = "cholesky", package = "cholmod";
  else if (ranks == 1 and structure == Structure::quasi_definite)
    package = "petsc";
  else if (structure == Structure::spd)
    pc = "cholesky";

  // A preconditioner other than a factorisation is no solver by itself:
  // then the default Krylov method is GMRES instead of a single application.
  char given_pc[64] = "";
  PetscBool set = PETSC_FALSE;
  PetscOptionsGetString(nullptr, prefix.c_str(), "-pc_type", given_pc, sizeof given_pc, &set);
  const bool direct = !set or std::string(given_pc) == "lu" or std::string(given_pc) == "cholesky";
  set_default_option(prefix + "ksp_type", direct ? "preonly" : "gmres");
  set_default_option(prefix + "pc_type", pc);
  if (!direct)
    return;
  if (set and std::string(given_pc) != pc)
    // The user chose the other factorisation: the package must take it.
    package = "mumps";
  set_default_option(prefix + "pc_factor_mat_solver_type", package);
  char used[64] = "";
  PetscOptionsGetString(nullptr, prefix.c_str(), "-pc_factor_mat_solver_type", used, sizeof used, nullptr);
  // An ordering given to MUMPS replaces its own analysis (far more fill):
  // only PETSc's factorisation gets nested dissection here.
  if (std::string(used) == "petsc")
    set_default_option(prefix + "pc_factor_mat_ordering_type", "nd");
  if (std::string(used) == "mumps")
    // More workspace than MUMPS's default: refactorisations of a changed
    // inactive set may need more pivoting room than the analysis planned.
    set_default_option(prefix + "mat_mumps_icntl_14", "400");
}

SolverStage::SolverStage(const std::string& name)
{
  // One stage per name for the whole process (a stage cannot be removed).
  static std::map<std::string, PetscLogStage> stages;
  auto it = stages.find(name);
  if (it == stages.end())
  {
    PetscLogStageRegister(name.c_str(), &_stage);
    stages[name] = _stage;
  }
  else
    _stage = it->second;
}

void SolverStage::read(SolverStatistics& s) const
{
  auto info = [&](const char* event)
  {
    PetscLogEvent id = 0;
    PetscEventPerfInfo perf{};
    if (PetscLogEventGetId(event, &id) == 0)
      PetscLogEventGetPerfInfo(_stage, id, &perf);
    return perf;
  };
  const PetscEventPerfInfo setup = info("PCSetUp"), solve = info("KSPSolve");
  s.setups = setup.count;
  s.setup_time = setup.time;
  s.back_solves = solve.count;
  s.solve_time = solve.time;
}

std::string system_name(const std::string& prefix) { return "the " + prefix.substr(0, prefix.size() - 1); }

LinearSolver::LinearSolver(MPI_Comm comm, const std::string& prefix, Mat A, Structure structure)
    : _prefix(prefix)
{
  if (structure == Structure::spd)
    MatSetOption(A, MAT_SPD, PETSC_TRUE);
  set_solver_defaults(prefix, structure, comm);
  KSPCreate(comm, &_ksp);
  KSPSetOptionsPrefix(_ksp, prefix.c_str());
  KSPSetOperators(_ksp, A, A);
  if (PetscErrorCode ierr = KSPSetFromOptions(_ksp); ierr != 0)
    throw OptionsError("the PETSc options of " + system_name(prefix) + " solver do not make a solver (PETSc error "
                       + std::to_string(ierr) + ")");
}

LinearSolver::~LinearSolver() { KSPDestroy(&_ksp); }

int LinearSolver::solve(Vec x, Vec b)
{
  return run([&] { return KSPSolve(_ksp, b, x); });
}

void LinearSolver::set_up()
{
  run([] { return PetscErrorCode(0); });
}

void LinearSolver::solve(Mat X, Mat B)
{
  run([&] { return KSPMatSolve(_ksp, B, X); });
}

int LinearSolver::run(const std::function<PetscErrorCode()>& solve)
{
  // Set-up first, so that the log keeps factorisation (PCSetUp) and
  // back-solve (KSPSolve) apart; a no-op while the operator is unchanged.
  PetscErrorCode ierr = KSPSetUp(_ksp);
  if (ierr == 0)
    ierr = solve();
  KSPConvergedReason reason = KSP_CONVERGED_ITERATING;
  KSPGetConvergedReason(_ksp, &reason);
  PC pc;
  KSPGetPC(_ksp, &pc);
  MatSolverType package = nullptr;
  PCFactorGetMatSolverType(pc, &package);
  if ((ierr != 0 or reason == KSP_DIVERGED_PC_FAILED) and package and std::string(package) == MATSOLVERPETSC)
  {
    // A quasi-definite matrix whose negative block is at round-off against
    // the rest (tiny S + L) can still meet a tiny pivot without pivoting:
    // factorise it once more with MUMPS, which pivots.
    PetscOptionsSetValue(nullptr, ("-" + _prefix + "pc_factor_mat_solver_type").c_str(), MATSOLVERMUMPS);
    PetscOptionsClearValue(nullptr, ("-" + _prefix + "pc_factor_mat_ordering_type").c_str());
    set_default_option(_prefix + "mat_mumps_icntl_14", "400");
    Mat A; // owned by the system: it outlives the reset
    KSPGetOperators(_ksp, &A, nullptr);
    KSPReset(_ksp);
    KSPSetOperators(_ksp, A, A);
    KSPSetFromOptions(_ksp);
    ierr = KSPSetUp(_ksp);
    if (ierr == 0)
      ierr = solve();
    KSPGetConvergedReason(_ksp, &reason);
  }
  if (ierr != 0)
    throw SolverError(system_name(_prefix) + " linear solver failed: PETSc error " + std::to_string(ierr));
  if (reason < 0)
    throw SolverError(system_name(_prefix) + " linear solver failed: " + KSPConvergedReasons[reason]);
  PetscInt its = 0;
  KSPGetIterationNumber(_ksp, &its);
  return static_cast<int>(its);
}

} // namespace biotcontact
