// Unit tests of the componentwise backward error (cpp/solvers/backward_error.h):
// at the round-off for the exact solution; an error in a row 1e20 below
// the other is seen as in any row (the closed form delta / (2 + delta),
// where ||b - A x|| / ||b|| is 1e-23); a row of zeros counts 0. The
// prototype's twin is tests/unit/test_backward_error.py.
#include "solvers/backward_error.h"
#include "dense.h"

#include <gtest/gtest.h>

using namespace biotcontact;
using namespace unit;

namespace
{
/// The backward error of x for A x = b, and the residual it leaves.
std::pair<double, std::vector<double>> error_of(const Dense& A, const std::vector<double>& x,
                                                const std::vector<double>& b)
{
  Mat M = petsc_matrix(A);
  Vec X = petsc_vector(M, x), B = petsc_vector(M, b), R = petsc_vector(M, std::vector<double>(A.n, 0.0));
  const double error = backward_error(M, X, B, R);
  const std::vector<double> r = values(R);
  for (Vec* v : {&X, &B, &R})
    VecDestroy(v);
  MatDestroy(&M);
  return {error, r};
}
} // namespace

TEST(BackwardError, ExactSolutionIsAtRoundOff)
{
  const Dense A = spd_matrix(4);
  const std::vector<double> x{1.0, -2.0, 3.0, 0.5};
  EXPECT_LE(error_of(A, x, product(A, x)).first, 4e-16);
}

TEST(BackwardError, SeesARowFarBelowTheOther)
{
  Dense A(2);
  A(0, 0) = 1.0, A(1, 1) = 1e-20;
  const double delta = 1e-3;
  const auto [error, r] = error_of(A, {1.0, 1.0 + delta}, {1.0, 1e-20});
  EXPECT_NEAR(error, delta / (2 + delta), 1e-12);
  EXPECT_EQ(r[0], 0.0);
  EXPECT_NEAR(r[1], -1e-20 * delta, 1e-35);
}

TEST(BackwardError, ARowOfZerosCountsZero)
{
  Dense A(2);
  A(0, 0) = 1.0;
  EXPECT_EQ(error_of(A, {1.0, 5.0}, {1.0, 0.0}).first, 0.0);
}
