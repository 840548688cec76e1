// A linear system's solver: a KSP with the options prefix of its system,
// set up anew only when the operator changes, a factorisation reused for a
// nudged operator, another package tried where a pivot fails, and a package
// the user names refined to a backward error (backward_error.h). Its
// defaults come from set_solver_defaults (solver.h).
#pragma once

#include "solvers/solver.h"

#include <functional>
#include <petscksp.h>
#include <string>
#include <vector>

namespace biotcontact
{

/// Sets the relative tolerance of a Krylov method, unless the command line
/// gave -<prefix>ksp_rtol (which wins). On the KSP itself, not in the
/// options database: SNES VI re-reads the options at every change of the
/// inactive set, which would undo a tolerance set by the coupling.
void set_relative_tolerance(KSP ksp, const std::string& prefix, double tolerance);

/// A KSP with an options prefix ("flow_", "mechanics_") whose defaults
/// were set by set_solver_defaults. A factorisation (or AMG set-up) is
/// redone only when the operator's values change (PETSc compares the matrix
/// state). An iterative solve starts from the x it is given (the previous
/// iterate or time step).
class LinearSolver
{
public:
  /// Solves with A, preconditioned from P (A itself, or the fixed-stress
  /// matrix of the coupled system); `fields` (optional) are the splits of
  /// a field split preconditioner.
  LinearSolver(MPI_Comm comm, const std::string& prefix, Mat A, Mat P, Structure structure,
               const std::vector<Field>& fields = {});
  ~LinearSolver();
  LinearSolver(const LinearSolver&) = delete;
  LinearSolver& operator=(const LinearSolver&) = delete;

  /// Solves A x = b; returns the Krylov iterations. Throws SolverError.
  /// A package named on the command line is checked and refined (refine).
  int solve(Vec x, Vec b);
  /// Factorises (sets up) now, if the operator changed. Throws SolverError.
  void set_up();
  /// Solves A X = B for the columns of the dense B (one call into the
  /// factorisation for all of them when it supports it). Throws SolverError.
  void solve(Mat X, Mat B);

  /// The relative tolerance of the next solves (a Krylov method only).
  void set_tolerance(double relative) { set_relative_tolerance(_ksp, _prefix, relative); }
  /// The operator's values changed: the next solve sets up anew (PETSc
  /// sees the new matrix state by itself; this only counts).
  void operator_changed() { _operator_changed = true, _stale = false; }
  /// The operator's values changed in a few rows (a fault's apertures):
  /// the solves that follow take the last factorisation as GMRES's
  /// preconditioner, to nearby_tolerance, and factorise anew only when
  /// that does not converge in nearby_iterations (a direct method only).
  /// nearby_tolerance lies above the round-off of a back-solve: GMRES's
  /// first iteration ends at 0.7-1.5e-14 on the 50-fracture network, where
  /// a tolerance of 1e-14 took a second iteration, which only stirs the
  /// round-off, in 15 of its 61 solves on one rank and 60 on two.
  void operator_nudged() { _stale = _stale or (_direct and setups > 0 and !_operator_changed); }
  static constexpr double nearby_tolerance = 1e-13;
  static constexpr int nearby_iterations = 10;
  /// Preconditioner set-ups (factorisations or AMG hierarchies) so far:
  /// one per operator, and the seconds they took.
  long setups = 0;
  double setup_time = 0;

private:
  /// Sets up (factorises if needed) and runs `solve`; throws SolverError
  /// when either fails or the solve diverged.
  void run(const std::function<PetscErrorCode()>& solve);
  /// Factorises the operator again with `package` and runs `solve`.
  PetscErrorCode refactorise(const char* package, const std::function<PetscErrorCode()>& solve,
                             KSPConvergedReason& reason);
  /// KSPSetUp, then `solve` if it succeeded: the first error code (0 when
  /// both succeed), agreed among the ranks (agreed_code); the set-up
  /// counted in setups and setup_time if `counted`.
  PetscErrorCode set_up_and_solve(const std::function<PetscErrorCode()>& solve, bool counted);
  /// `solve` by GMRES preconditioned by the stale factorisation: whether
  /// it converged (else the next solve factorises).
  bool solve_nearby(const std::function<PetscErrorCode()>& solve);
  /// Iterative refinement of the solve x of A x = b by a package the user
  /// named until its backward error meets backward_error_tolerance; throws
  /// SolverError when refinement_steps do not reach it (such a package may
  /// pivot by magnitude alone on rows 1e22 apart; preonly has no test).
  void refine(Vec x, Vec b);
  KSP _ksp;
  std::string _prefix;
  bool _operator_changed = true; // the next solve sets up
  bool _direct = false;          // a factorisation (preonly)
  bool _stale = false;           // the factorisation is of an operator since nudged
  bool _checked = false;         // a package the user named (refine)
};

} // namespace biotcontact
