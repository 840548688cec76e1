// Unit tests of the PETSc options the solvers refuse (cpp/solvers/options.h):
// SuperLU_DIST named with several OpenMP threads, under any prefix, is one
// line naming the option; one thread, or no SuperLU_DIST, is no error; a
// relative tolerance outside [0, 1) is one line naming it. The prototype's
// twin is tests/unit/test_options.py.
#include "solvers/options.h"

#include <gtest/gtest.h>

using namespace biotcontact;

TEST(SolverOptions, SuperluWithThreadsIsRefusedByItsOption)
{
  const std::string all = "-mechanics_contact_snes_monitor -flow_pc_factor_mat_solver_type superlu_dist -log_view";
  EXPECT_EQ(threaded_superlu(all, 2), "-flow_pc_factor_mat_solver_type superlu_dist: SuperLU_DIST solves wrongly "
                                      "with 2 OpenMP threads (Debian's 8.1.2: the contact solver cycles, the split "
                                      "diverges); set OMP_NUM_THREADS=1");
  EXPECT_NE(threaded_superlu("-monolithic_redundant_pc_factor_mat_solver_type superlu_dist", 8).find(
                "-monolithic_redundant_pc_factor_mat_solver_type superlu_dist:"),
            std::string::npos);
}

TEST(SolverOptions, OneThreadOrAnotherPackageIsNoError)
{
  EXPECT_EQ(threaded_superlu("-flow_pc_factor_mat_solver_type superlu_dist", 1), "");
  EXPECT_EQ(threaded_superlu("-flow_pc_factor_mat_solver_type mumps -mechanics_pc_type cholesky", 2), "");
  EXPECT_EQ(threaded_superlu("", 2), "");
}

TEST(SolverOptions, ARelativeToleranceOutsideZeroToOneIsRefused)
{
  EXPECT_EQ(relative_tolerance_out_of_range("-log_view -mechanics_snes_rtol 2 -flow_ksp_rtol 1e-8"),
            "-mechanics_snes_rtol 2: a relative tolerance lies in [0, 1) (from 1 on any first iterate meets it)");
  EXPECT_NE(relative_tolerance_out_of_range("-flow_ksp_rtol -1e-3").find("-flow_ksp_rtol -1e-3:"), std::string::npos);
  EXPECT_NE(relative_tolerance_out_of_range("-ksp_rtol 1").find("-ksp_rtol 1:"), std::string::npos);
  EXPECT_EQ(relative_tolerance_out_of_range("-mechanics_snes_rtol 0.5 -flow_ksp_rtol 0 -monolithic_ksp_atol 5"), "");
  EXPECT_EQ(relative_tolerance_out_of_range("-flow_ksp_rtol"), ""); // no value: PETSc's own error
}
