// What one system's solver did, and the PETSc log stage it is read from:
// set-ups (PCSetUp) and back-solves (KSPSolve) of the system's own stage,
// so the counts are what PETSc did and `-log_view` shows them stage by
// stage. Twin: python_prototype/solvers/solver_statistics.py.
#pragma once

#include "assembly/petsc_error.h"

#include <array>
#include <petsclog.h>
#include <string>
#include <utility>

namespace biotcontact
{

/// What one system's solver did, read from its PETSc log stage.
struct SolverStatistics
{
  long solves = 0;            // calls of the system's solve
  long setups = 0;            // factorisations (direct) or AMG hierarchies (iterative)
  long back_solves = 0;       // KSP solves (Newton steps of a contact solve)
  long linear_iterations = 0; // Krylov iterations (1 per back-solve when direct)
  long newton_iterations = 0; // contact (SNES VI) Newton steps
  long active_set_changes = 0;
  long schur_columns = 0;     // right-hand sides solved to form a contact Schur complement
  long schur_factorizations = 0; // partial factorisations that left one (MUMPS)
  long contact_factorizations = 0; // the condensed contact solve's (its own log stage)
  double setup_time = 0;      // s in PCSetUp
  double solve_time = 0;      // s in KSPSolve: the back-solves
  double total_time = 0;      // s in the system's solve, all included
  double assembly_time = 0;   // s assembling its matrix
  double schur_time = 0;      // s forming a contact Schur complement from its factorisation
};

/// The counts of SolverStatistics by name: the one list that checkpoints,
/// restarts and the sum with an earlier run's counts read.
inline constexpr std::array<std::pair<const char*, long SolverStatistics::*>, 9> solver_counts{{
    {"solves", &SolverStatistics::solves},
    {"setups", &SolverStatistics::setups},
    {"back_solves", &SolverStatistics::back_solves},
    {"linear_iterations", &SolverStatistics::linear_iterations},
    {"newton_iterations", &SolverStatistics::newton_iterations},
    {"active_set_changes", &SolverStatistics::active_set_changes},
    {"schur_columns", &SolverStatistics::schur_columns},
    {"schur_factorizations", &SolverStatistics::schur_factorizations},
    {"contact_factorizations", &SolverStatistics::contact_factorizations},
}};

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
    explicit Guard(const SolverStage& s)
    {
      check_petsc(PetscLogStagePush(s._stage), "a solver's log stage: PetscLogStagePush");
    }
    ~Guard() { warn_petsc(PetscLogStagePop(), "a solver's log stage: PetscLogStagePop"); }
  };

private:
  PetscLogStage _stage = 0;
};

} // namespace biotcontact
