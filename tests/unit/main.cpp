// The main of the C++ unit tests: GoogleTest inside PETSc (which starts
// MPI), since the contact algebra works on PETSc matrices and the solver's
// factorisations. Listing the tests (gtest_discover_tests, at build time)
// needs neither, and skips them.
#include <cstdio>
#include <cstdlib>
#include <gtest/gtest.h>
#include <petscsys.h>

int main(int argc, char* argv[])
{
  testing::InitGoogleTest(&argc, argv);
  if (GTEST_FLAG_GET(list_tests))
    return RUN_ALL_TESTS();
  // Open MPI's start-up as the solver's main.cpp sets it: a singleton
  // without its helper daemon and without a session directory (isolated
  // singletons share one, and a process removing it while another creates
  // it fails MPI_Init), shared memory without trying UCX first; a value
  // set outside the tests is kept.
  setenv("OMPI_MCA_ess_singleton_isolated", "1", 0);
  setenv("OMPI_MCA_orte_create_session_dirs", "0", 0);
  setenv("OMPI_MCA_pml", "ob1", 0);
  if (PetscInitialize(&argc, &argv, nullptr, nullptr) != 0)
  {
    std::fprintf(stderr, "unit_tests: PetscInitialize failed\n");
    return 1;
  }
  const int status = RUN_ALL_TESTS();
  return PetscFinalize() != 0 ? 1 : status;
}
