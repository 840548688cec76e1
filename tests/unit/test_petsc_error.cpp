// Unit tests of the ranks' agreement on a PETSc error code
// (cpp/assembly/petsc_error.h, agreed_code): a code one rank's call
// returned reaches every rank, the largest where several failed, and 0
// only where all succeeded. Meant for two ranks (ctest unit.two_ranks runs
// this suite under mpirun -n 2); on one it checks the code passes through.
// The prototype's twin is tests/unit/test_petsc_error.py.
#include "assembly/petsc_error.h"

#include <gtest/gtest.h>

using namespace biotcontact;

TEST(PetscError, OneRanksFailureReachesEveryRank)
{
  int rank = 0, size = 1;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  const bool last = rank == size - 1;
  EXPECT_EQ(agreed_code(last ? PETSC_ERR_MAT_LU_ZRPVT : 0, MPI_COMM_WORLD), PETSC_ERR_MAT_LU_ZRPVT);
  EXPECT_EQ(agreed_code(last ? PETSC_ERR_MEM : PETSC_ERR_MAT_LU_ZRPVT, MPI_COMM_WORLD),
            size > 1 ? PETSC_ERR_MAT_LU_ZRPVT : PETSC_ERR_MEM); // the largest: ZRPVT 71 > MEM 55
  EXPECT_EQ(agreed_code(0, MPI_COMM_WORLD), 0);
}
