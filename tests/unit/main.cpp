// The main of the C++ unit tests: GoogleTest inside PETSc (which starts
// MPI), since the contact algebra works on PETSc matrices and the solver's
// factorisations. Listing the tests (gtest_discover_tests, at build time)
// needs neither, and skips them.
#include <cstdlib>
#include <gtest/gtest.h>
#include <petscsys.h>

int main(int argc, char* argv[])
{
  testing::InitGoogleTest(&argc, argv);
  if (GTEST_FLAG_GET(list_tests))
    return RUN_ALL_TESTS();
  // Open MPI's start-up as tests/support.py sets it for every run: a
  // singleton without its helper daemon, shared memory without trying UCX
  // first (0.33 of the 0.35 s MPI_Init takes otherwise); a value set
  // outside the tests is kept.
  setenv("OMPI_MCA_ess_singleton_isolated", "1", 0);
  setenv("OMPI_MCA_pml", "ob1", 0);
  PetscInitialize(&argc, &argv, nullptr, nullptr);
  const int status = RUN_ALL_TESTS();
  PetscFinalize();
  return status;
}
