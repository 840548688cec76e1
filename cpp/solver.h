// How a system is solved: the one place that chooses the factorisation (or,
// when the command line asks for one, the Krylov method), says when a
// factorisation may be reused, and counts set-ups and solves per system.
//
// Every system (flow, mechanics, monolithic) has its own options prefix and
// its own PETSc log stage; set-ups (PCSetUp: one factorisation for a direct
// solver) and back-solves (KSPSolve) are read from PETSc's event log of that
// stage, so they count what PETSc really did, and `-log_view` shows the same
// numbers stage by stage.
#pragma once

#include <functional>
#include <mpi.h>
#include <petscksp.h>
#include <petsclog.h>
#include <stdexcept>
#include <string>

namespace biotcontact
{

/// A solver that did not converge: the run stops with this message.
struct SolverError : std::runtime_error
{
  using std::runtime_error::runtime_error;
};

/// PETSc options that do not make a solver: bad input (exit 2).
struct OptionsError : std::runtime_error
{
  using std::runtime_error::runtime_error;
};

/// What the factorisation may assume of a matrix.
enum class Structure
{
  /// Symmetric positive definite (elasticity with Dirichlet rows): Cholesky.
  spd,
  /// Nonsingular with nonzero diagonal blocks of opposite signs after a
  /// symmetric row scaling (RT0 x P0 with S + L > 0, the coupled system with
  /// S > 0): LU without pivoting is stable in any symmetric ordering
  /// (Vanderbei's quasi-definite matrices).
  quasi_definite,
  /// Anything else (a zero diagonal block, S = 0): LU with pivoting.
  general
};

/// Sets the defaults of the solver with this options prefix unless the
/// command line gave them: a direct solve (preonly), with the factorisation
/// measured fastest for the structure on this communicator
/// (docs/performance.md): on one rank CHOLMOD Cholesky for SPD matrices and
/// PETSc's own nested-dissection LU for quasi-definite ones, MUMPS
/// otherwise and on several ranks. A -<prefix>pc_type that is no
/// factorisation makes GMRES the default Krylov method.
void set_solver_defaults(const std::string& prefix, Structure structure, MPI_Comm comm);

/// Sets a PETSc option unless the user already gave it (command line wins).
void set_default_option(const std::string& name, const std::string& value);

/// What one system's solver did, read from its PETSc log stage.
struct SolverStatistics
{
  long solves = 0;            // calls of the system's solve
  long setups = 0;            // preconditioner set-ups = factorisations when direct
  long back_solves = 0;       // KSP solves (Newton steps of a contact solve)
  long linear_iterations = 0; // Krylov iterations (1 per back-solve when direct)
  long newton_iterations = 0; // contact (SNES VI) Newton steps
  long active_set_changes = 0;
  long schur_columns = 0;     // right-hand sides solved to form a contact Schur complement
  double setup_time = 0;      // s in PCSetUp
  double solve_time = 0;      // s in KSPSolve: the back-solves
  double total_time = 0;      // s in the system's solve, all included
  double assembly_time = 0;   // s assembling its matrix
  double schur_time = 0;      // s forming a contact Schur complement from its factorisation
};

/// A PETSc log stage named after a system; pushed while the system solves.
class SolverStage
{
public:
  explicit SolverStage(const std::string& name);
  /// Reads set-ups, back-solves and their times from the event log.
  void read(SolverStatistics& statistics) const;

  /// Pushes the stage for the lifetime of the guard.
  struct Guard
  {
    explicit Guard(const SolverStage& s) { PetscLogStagePush(s._stage); }
    ~Guard() { PetscLogStagePop(); }
  };

private:
  PetscLogStage _stage = 0;
};

/// A KSP with an options prefix ("flow_", "mechanics_"); a direct solve by
/// default (set_solver_defaults). The factorisation is redone only when the
/// operator's values change (PETSc compares the matrix state).
class LinearSolver
{
public:
  LinearSolver(MPI_Comm comm, const std::string& prefix, Mat A, Structure structure);
  ~LinearSolver();
  LinearSolver(const LinearSolver&) = delete;
  LinearSolver& operator=(const LinearSolver&) = delete;

  /// Solves A x = b; returns the Krylov iterations. Throws SolverError.
  int solve(Vec x, Vec b);
  /// Factorises (sets up) now, if the operator changed. Throws SolverError.
  void set_up();
  /// Solves A X = B for the columns of the dense B (one call into the
  /// factorisation for all of them when it supports it). Throws SolverError.
  void solve(Mat X, Mat B);

private:
  /// Sets up (factorises if needed) and runs `solve`; checks the result.
  int run(const std::function<PetscErrorCode()>& solve);
  KSP _ksp;
  std::string _prefix;
};

/// "the mechanics" from "mechanics_".
std::string system_name(const std::string& prefix);

} // namespace biotcontact
