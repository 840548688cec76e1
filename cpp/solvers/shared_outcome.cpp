#include "solvers/shared_outcome.h"

#include "assembly/petsc_error.h"

namespace biotcontact
{

SolveOutcome shared_outcome(const SolveOutcome& mine, Vec y, MPI_Comm comm)
{
  int size = 1;
  MPI_Comm_size(comm, &size);
  if (size == 1)
    return mine;
  int head[2] = {mine.reason, static_cast<int>(mine.failure.size())};
  MPI_Bcast(head, 2, MPI_INT, 0, comm);
  SolveOutcome shared{head[0], mine.failure};
  shared.failure.resize(static_cast<std::size_t>(head[1]));
  MPI_Bcast(shared.failure.data(), head[1], MPI_CHAR, 0, comm);
  PetscInt n = 0;
  check_petsc(VecGetLocalSize(y, &n), "shared_outcome: VecGetLocalSize");
  PetscScalar* values = nullptr;
  check_petsc(VecGetArray(y, &values), "shared_outcome: VecGetArray");
  MPI_Bcast(values, static_cast<int>(n), MPIU_SCALAR, 0, comm);
  check_petsc(VecRestoreArray(y, &values), "shared_outcome: VecRestoreArray");
  return shared;
}

} // namespace biotcontact
