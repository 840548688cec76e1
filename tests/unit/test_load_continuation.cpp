// Unit tests of the continuation in the load (cpp/contact/load_continuation.h),
// with a solve that converges only from within `reach` of its solution
// (the identity: x = b): from the solved load 0 to 1, steps of 1/2 fail
// and quarters pass (0.25, 0.5, 0.75, 1: the solution 1); a reach below
// the smallest step (1/64), or too few solves, leaves x as it was; every
// solve starts where the last passed. The prototype's twin is
// tests/unit/test_load_continuation.py.
#include "assembly/petsc_error.h"
#include "contact/load_continuation.h"

#include <cmath>
#include <gtest/gtest.h>
#include <vector>

using namespace biotcontact;

namespace
{
struct Reach
{
  double reach;
  std::vector<double> tried;
  std::vector<double> passed;
  /// Solves x = b from x (in place) when |b - x| <= reach.
  void operator()(Vec b, Vec x)
  {
    double bv, xv;
    PetscInt i = 0;
    VecGetValues(b, 1, &i, &bv);
    VecGetValues(x, 1, &i, &xv);
    tried.push_back(bv);
    if (std::abs(bv - xv) > reach)
      throw SolverError("out of reach");
    VecCopy(b, x);
    passed.push_back(bv);
  }
};

double value(Vec v)
{
  double a;
  PetscInt i = 0;
  VecGetValues(v, 1, &i, &a);
  return a;
}

Vec scalar(double a)
{
  Vec v;
  VecCreateSeq(PETSC_COMM_SELF, 1, &v);
  VecSet(v, a);
  return v;
}

/// Continues from the solved load 0 to the load 1 with `reach`.
std::pair<bool, double> continued(Reach& solve, int max_solves)
{
  Vec zero = scalar(0), target = scalar(1), x = scalar(-7);
  SolvedLoad from;
  from.keep(zero, zero);
  const bool reached
      = continue_load(from, target, x, [&](Vec b, Vec y) { solve(b, y); }, max_solves);
  const double result = value(x);
  for (Vec* v : {&zero, &target, &x})
    VecDestroy(v);
  return {reached, result};
}
} // namespace

TEST(LoadContinuation, ReachesTheLoadInShorterSteps)
{
  Reach solve{0.3, {}, {}};
  const auto [reached, x] = continued(solve, 12);
  EXPECT_TRUE(reached);
  EXPECT_DOUBLE_EQ(x, 1.0);
  EXPECT_EQ(solve.passed, (std::vector<double>{0.25, 0.5, 0.75, 1.0}));
  EXPECT_EQ(solve.tried.front(), 0.5); // the first step, out of reach
}

TEST(LoadContinuation, LeavesXWhereItCannotReach)
{
  Reach short_reach{0.01, {}, {}}; // below the smallest step, 1/64
  const auto [reached, x] = continued(short_reach, 12);
  EXPECT_FALSE(reached);
  EXPECT_DOUBLE_EQ(x, -7.0);
  EXPECT_TRUE(short_reach.passed.empty());
  Reach few{0.3, {}, {}};
  const auto [reached_few, x_few] = continued(few, 3); // 0.5 fails, 0.25 and 0.5 pass
  EXPECT_FALSE(reached_few);
  EXPECT_DOUBLE_EQ(x_few, -7.0);
  EXPECT_EQ(few.passed, (std::vector<double>{0.25, 0.5}));
}

TEST(LoadContinuation, ForgetsWhenTheOperatorChanges)
{
  Vec b = scalar(2);
  SolvedLoad solved;
  EXPECT_FALSE(solved.known());
  solved.keep(b, b);
  EXPECT_TRUE(solved.known());
  EXPECT_DOUBLE_EQ(value(solved.load()), 2.0);
  solved.forget();
  EXPECT_FALSE(solved.known());
  VecDestroy(&b);
}
