// The whole system a contact VI may be posed on (variational_inequality.h),
// and its solve with some unknowns held: the clamped start's (all contact
// DOFs on their bounds, every frictional constraint stuck).
#pragma once

#include "solvers/solver.h"

#include <mpi.h>
#include <petscmat.h>
#include <vector>

namespace biotcontact
{

/// @brief The whole system a VI is posed on (y = x, K = A): its matrices,
/// fields and method. The clamped start solves it with the contact DOFs
/// eliminated; the iterative method preconditions the Newton steps from P
/// split along the fields (inactive_set_preconditioner.h).
struct WholeSystem
{
  MPI_Comm comm;
  Mat A, P;
  SystemLayout layout;
  Method method;
};

/// Solves A y = b with the global rows `rows` held at their values in y:
/// their rows and columns eliminated, the known values moved to the
/// right-hand side (collective).
void solve_clamped(const WholeSystem& whole, Vec b, Vec y, const std::vector<PetscInt>& rows);

} // namespace biotcontact
