// Unit tests of the tied unknowns (cpp/assembly/tied_dofs.h): the tied system
// A' = P^T A P (rows and columns j identity) is symmetric, and its solution,
// expanded, satisfies the ties x_j = s x_i and the optimality conditions of
// the constrained problem: A x - b is zero at the free unknowns, and at a
// tie's pair (i, j) it is the multiplier's, r_i = -s r_j. Reassembly reuses
// A''s structure. The prototype's twin is tests/unit/test_tied_dofs.py.
#include "assembly/tied_dofs.h"
#include "dense.h"

#include <gtest/gtest.h>

using namespace biotcontact;
using namespace unit;

namespace
{
const std::vector<Tie> ties = {{1, 3, -2.0}, {0, 4, 0.5}};
const std::vector<double> load = {1.0, 2.0, 3.0, 4.0, 5.0};

/// x = P y for y solving A' y = b' (dense elimination).
std::vector<double> tied_solution(const TiedDofs& tied, Mat A, Mat At)
{
  Vec b = petsc_vector(A, load), bt = petsc_vector(A, load), x = petsc_vector(A, load);
  tied.load(b, bt);
  const std::vector<double> y = solve(dense(At), {values(bt)})[0];
  Vec yv = petsc_vector(A, y);
  tied.expand(yv, x);
  std::vector<double> result = values(x);
  for (Vec* v : {&b, &bt, &x, &yv})
    VecDestroy(v);
  return result;
}
} // namespace

TEST(TiedDofs, TiedSystemIsSymmetricWithIdentityRows)
{
  Mat A = petsc_matrix(spd_matrix(5)), At = nullptr;
  TiedDofs tied(A, ties);
  EXPECT_EQ(tied.size(), 2);
  tied.reduce(A, &At);
  const Dense D = dense(At);
  for (int i = 0; i < 5; ++i)
    for (int j = 0; j < 5; ++j)
    {
      EXPECT_NEAR(D(i, j), D(j, i), 1e-14) << i << ", " << j;
      if (i >= 3 or j >= 3)
        EXPECT_EQ(D(i, j), i == j ? 1.0 : 0.0) << i << ", " << j;
    }
  MatDestroy(&At);
  MatDestroy(&A);
}

TEST(TiedDofs, SolutionSatisfiesTiesAndOptimality)
{
  const Dense dA = spd_matrix(5);
  Mat A = petsc_matrix(dA), At = nullptr;
  TiedDofs tied(A, ties);
  tied.reduce(A, &At);
  const std::vector<double> x = tied_solution(tied, A, At);
  EXPECT_DOUBLE_EQ(x[3], -2.0 * x[1]);
  EXPECT_DOUBLE_EQ(x[4], 0.5 * x[0]);
  std::vector<double> r = product(dA, x);
  for (int k = 0; k < 5; ++k)
    r[k] -= load[k];
  const double scale = largest(load);
  EXPECT_NEAR(r[2], 0.0, 1e-14 * scale) << "a free unknown's equation holds";
  EXPECT_GT(std::abs(r[3]), 1e-3 * scale) << "the tie carries a force";
  for (const Tie& t : ties)
    EXPECT_NEAR(r[t.i], -t.s * r[t.j], 1e-14 * scale) << "tie " << t.i << " - " << t.j;
  MatDestroy(&At);
  MatDestroy(&A);
}

TEST(TiedDofs, ReassemblyReusesTheStructure)
{
  Dense dA = spd_matrix(5);
  Mat A = petsc_matrix(dA), At = nullptr;
  TiedDofs tied(A, ties);
  tied.reduce(A, &At);
  const Dense once = dense(At);
  MatScale(A, 3.0);
  Mat same = At;
  tied.reduce(A, &At);
  EXPECT_EQ(At, same);
  const Dense again = dense(At);
  for (int i = 0; i < 5; ++i)
    for (int j = 0; j < 5; ++j)
      EXPECT_NEAR(again(i, j), (i >= 3 or j >= 3) ? once(i, j) : 3 * once(i, j), 1e-13) << i << ", " << j;
  MatDestroy(&At);
  MatDestroy(&A);
}
