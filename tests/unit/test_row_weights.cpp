// Unit tests of the balanced rows (cpp/solvers/row_weights.h): the leaves
// of nested field splits are the system's rows; the weights make every
// leaf's largest entry the matrix's largest, one constant per leaf; and
// W K y = W b has the solution of K y = b, with W J rebuilt when K or J
// changes. The prototype's twin is tests/unit/test_row_weights.py.
#include "solvers/row_weights.h"
#include "dense.h"

#include <gtest/gtest.h>

using namespace biotcontact;
using namespace unit;

namespace
{
/// A coupled system's fields on 7 rows: the displacement (0-2) and the flow
/// (3-6), split into the flux (3, 4) and the pressure (5, 6).
std::vector<Field> coupled_fields()
{
  Field mechanics("mechanics", {0, 1, 2}), flow("flow", {3, 4, 5, 6});
  flow.fields = {part_of(flow, "flux", {3, 4}, PETSC_COMM_WORLD), part_of(flow, "pressure", {5, 6}, PETSC_COMM_WORLD)};
  return {mechanics, flow};
}

/// spd_matrix(7) with the flux rows times 1e-6 and the pressure rows times
/// 1e-9 (a coupled system's rows in their own units).
Dense unbalanced()
{
  Dense A = spd_matrix(7);
  for (int i = 3; i < 7; ++i)
    for (int j = 0; j < 7; ++j)
      A(i, j) *= i < 5 ? 1e-6 : 1e-9;
  return A;
}
} // namespace

TEST(RowWeights, LeavesAreTheSystemsRows)
{
  const auto leaves = leaf_rows(coupled_fields(), PETSC_COMM_WORLD);
  ASSERT_EQ(leaves.size(), 3u);
  EXPECT_EQ(leaves[0], (std::vector<PetscInt>{0, 1, 2}));
  EXPECT_EQ(leaves[1], (std::vector<PetscInt>{3, 4}));
  EXPECT_EQ(leaves[2], (std::vector<PetscInt>{5, 6}));
}

TEST(RowWeights, EveryLeafsLargestEntryBecomesTheMatrixs)
{
  const Dense A = unbalanced();
  Mat M = petsc_matrix(A);
  Vec w = petsc_vector(M, std::vector<double>(7, 0.0));
  set_balancing_weights(M, leaf_rows(coupled_fields(), PETSC_COMM_WORLD), w);
  const std::vector<double> W = values(w);
  EXPECT_EQ(W[0], 1.0); // the displacement's rows hold the largest entry
  EXPECT_EQ(W[3], W[4]);
  EXPECT_EQ(W[5], W[6]);
  const double m = 1.0 + 7; // spd_matrix's diagonal
  for (int leaf_start : {0, 3, 5})
  {
    double largest_entry = 0;
    for (int i = leaf_start; i < (leaf_start == 0 ? 3 : leaf_start + 2); ++i)
      for (int j = 0; j < 7; ++j)
        largest_entry = std::max(largest_entry, std::abs(W[i] * A(i, j)));
    EXPECT_NEAR(largest_entry, m, 1e-14 * m) << "leaf from row " << leaf_start;
  }
  VecDestroy(&w);
  MatDestroy(&M);
}

TEST(RowWeights, BalancedSystemHasTheSameSolution)
{
  const Dense A = unbalanced();
  Mat K = petsc_matrix(A);
  const std::vector<double> load = {1.0, 2.0, 3.0, 4e-6, 5e-6, 6e-9, 7e-9};
  Vec b = petsc_vector(K, load);
  BalancedRows balanced(K, coupled_fields(), PETSC_COMM_WORLD);
  balanced.pose(K, K, b);
  const std::vector<double> x = solve(A, {load})[0];
  const std::vector<double> y = solve(dense(balanced.jacobian()), {values(balanced.load())})[0];
  for (int i = 0; i < 7; ++i)
    EXPECT_NEAR(y[i], x[i], 1e-12 * largest(x)) << i;
  // K reassembled (twice its values): W K follows, the weights unchanged.
  MatScale(K, 2.0);
  balanced.operator_changed();
  balanced.pose(K, K, b);
  const Dense WK = dense(balanced.jacobian());
  const std::vector<double> W = values(balanced.weights());
  for (int i = 0; i < 7; ++i)
    for (int j = 0; j < 7; ++j)
      EXPECT_NEAR(WK(i, j), 2.0 * W[i] * A(i, j), 1e-15 * 8 * 2) << i << ", " << j;
  VecDestroy(&b);
  MatDestroy(&K);
}
