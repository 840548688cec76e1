// A problem each rank solves alone, the same problem on every rank (the
// condensed contact VI, contact/contact.h): the same outcome in exact
// arithmetic, not always in floating point (threads, another node's
// kernels). Rank 0's outcome becomes every rank's, so that what the ranks
// decide from it, and their next collective calls, are the same.
#pragma once

#include <mpi.h>
#include <petscvec.h>
#include <string>

namespace biotcontact
{

/// @brief How a solve ended on a rank: its converged reason (PETSc's:
/// negative when it diverged) and, when it failed, the failure's text.
struct SolveOutcome
{
  int reason = 0;
  std::string failure; // empty unless the solve failed
};

/// Rank 0's outcome, and rank 0's values of `y` (a sequential vector of the
/// same size on every rank), on every rank of `comm` (collective).
SolveOutcome shared_outcome(const SolveOutcome& mine, Vec y, MPI_Comm comm);

} // namespace biotcontact
