// Unit tests of a solve's record (cpp/steps/solve_record.h), a row of
// iterations.csv for the schemes with one solve per step: the l2 norms of
// each field and of its change since start(), counting only the values a
// rank owns (ghosts and copies left out), NaN for a field the step has
// not, and the Newton steps taken in between. The prototype's twin is
// tests/unit/test_solve_record.py.
#include "steps/solve_record.h"

#include <cmath>
#include <gtest/gtest.h>
#include <vector>

using namespace biotcontact;

TEST(SolveRecord, NormsOfEachFieldAndItsChange)
{
  // p has 2 owned values and a ghost, u 3 owned; no p_f.
  std::vector<double> p{3.0, 4.0, 100.0}, u{1.0, 2.0, 2.0};
  SolveMeter meter;
  meter.start({{p, 2, true}, {u, 3, true}, {}, MPI_COMM_WORLD}, 7);
  p = {0.0, 4.0, -50.0}; // change (-3, 0): the ghost's -150 not counted
  u = {1.0, 2.0, 4.0};   // change (0, 0, 2)
  const SolveRecord r = meter.record({{p, 2, true}, {u, 3, true}, {}, MPI_COMM_WORLD}, 10, 5);
  EXPECT_DOUBLE_EQ(r.dp, 3.0);
  EXPECT_DOUBLE_EQ(r.p, 4.0);
  EXPECT_DOUBLE_EQ(r.du, 2.0);
  EXPECT_DOUBLE_EQ(r.u, std::sqrt(21.0));
  EXPECT_TRUE(std::isnan(r.fault_dp) and std::isnan(r.fault_p)) << "a step without conduit faults";
  EXPECT_EQ(r.newton_steps, 3);
  EXPECT_EQ(r.active_nodes, 5);
}

TEST(SolveRecord, AFieldHeldByAnotherRankCountsNothingHere)
{
  // p_f held by the last rank: here (one rank) all of it, with owned = 0
  // nothing, as on the other ranks.
  std::vector<double> p_f{1.0, 1.0};
  SolveMeter meter;
  meter.start({{}, {}, {p_f, 0, true}, MPI_COMM_WORLD}, 0);
  p_f = {3.0, 5.0};
  const SolveRecord r = meter.record({{}, {}, {p_f, 0, true}, MPI_COMM_WORLD}, 0, 0);
  EXPECT_EQ(r.fault_dp, 0.0);
  EXPECT_EQ(r.fault_p, 0.0);
  EXPECT_TRUE(std::isnan(r.dp) and std::isnan(r.du));
}
