// Unit tests of the quick analysis of repeated factorisations
// (cpp/contact/factorization_reuse.h): MUMPS analyses by AMD a matrix of at
// most quick_analysis_rows rows, also a copy on each rank, and leaves a
// larger one, another package and a user's choice alone. The prototype's
// twin is tests/unit/test_quick_analysis.py.
#include "contact/factorization_reuse.h"
#include "solvers/solver.h"

#include <gtest/gtest.h>
#include <petscmat.h>

using namespace biotcontact;

namespace
{
/// An empty sequential matrix of `rows` rows (analyse_quickly reads its size).
Mat empty_matrix(PetscInt rows)
{
  Mat K = nullptr;
  EXPECT_EQ(MatCreateSeqAIJ(PETSC_COMM_SELF, rows, rows, 0, nullptr, &K), 0);
  return K;
}

/// The ordering analyse_quickly chose for `prefix` after `options` were given.
std::string ordering(const std::string& options, const std::string& prefix, PetscInt rows)
{
  EXPECT_EQ(PetscOptionsInsertString(nullptr, options.c_str()), 0);
  Mat K = empty_matrix(rows);
  analyse_quickly(prefix, K);
  EXPECT_EQ(MatDestroy(&K), 0);
  return option(prefix, "-mat_mumps_icntl_7") + "|" + option(prefix + "redundant_", "-mat_mumps_icntl_7");
}
} // namespace

TEST(QuickAnalysis, MumpsAnalysesByAmdUpToTheLimit)
{
  EXPECT_EQ(ordering("-qa1_pc_factor_mat_solver_type mumps", "qa1_", 1000), "0|");
  EXPECT_EQ(ordering("-qa2_pc_factor_mat_solver_type mumps", "qa2_", quick_analysis_rows), "0|");
  EXPECT_EQ(ordering("-qa3_pc_type redundant -qa3_redundant_pc_factor_mat_solver_type mumps", "qa3_", 1000), "|0");
}

TEST(QuickAnalysis, LargerSystemsOtherPackagesAndTheUserKeepTheirs)
{
  EXPECT_EQ(ordering("-qa4_pc_factor_mat_solver_type mumps", "qa4_", quick_analysis_rows + 1), "|");
  EXPECT_EQ(ordering("-qa5_pc_factor_mat_solver_type umfpack", "qa5_", 1000), "|");
  EXPECT_EQ(ordering("-qa6_pc_factor_mat_solver_type mumps -qa6_mat_mumps_icntl_7 5", "qa6_", 1000), "5|");
}
