// Unit tests of a coupling iteration's cycle and stagnation
// (cpp/coupling/cycle.h): a contact set returning every P iterations with
// increments that do not shrink is a cycle of period P, the smallest; a set
// that stays, increments that shrink by more than 0.05 % a period, or too
// few iterations are none. A steady rate that cannot reach the tolerance in
// the iterations left stagnates; a faster, unsteady or early one does not.
// The prototype's twin is tests/unit/test_cycle.py.
#include "coupling/cycle.h"

#include <gtest/gtest.h>
#include <vector>

#include <cmath>

using namespace biotcontact;

namespace
{
/// `periods` repetitions of `pattern`, increments scaled by `rate` per period.
std::pair<std::vector<std::int64_t>, std::vector<double>> repeated(const std::vector<std::int64_t>& pattern,
                                                                   int periods, double rate)
{
  std::vector<std::int64_t> active;
  std::vector<double> increments;
  double scale = 1;
  for (int k = 0; k < periods; ++k, scale *= rate)
    for (std::size_t i = 0; i < pattern.size(); ++i)
      active.push_back(pattern[i]), increments.push_back(scale * (1.0 + i));
  return {active, increments};
}
} // namespace

TEST(Cycle, PeriodOfTheContactSet)
{
  // The split's period-4 cycle at a pair's kink (117 nodes: the pair open).
  const auto [a4, i4] = repeated({117, 117, 118, 118}, 3, 1.0);
  EXPECT_EQ(cycle_period(a4, i4), 4);
  const auto [a2, i2] = repeated({52, 57}, 3, 1.0);
  EXPECT_EQ(cycle_period(a2, i2), 2);
  const auto [a3, i3] = repeated({271, 274, 274}, 3, 0.9998); // within 0.05 % a period
  EXPECT_EQ(cycle_period(a3, i3), 3);
  // Growing increments cycle too.
  const auto [ag, ig] = repeated({117, 117, 118, 118}, 3, 1.5);
  EXPECT_EQ(cycle_period(ag, ig), 4);
}

TEST(Cycle, NoneWhereTheIterationProgresses)
{
  const auto [a, i] = repeated({117, 117, 118, 118}, 3, 0.998); // shrinking by 0.2 % a period
  EXPECT_EQ(cycle_period(a, i), 0);
  const auto [s, is] = repeated({118, 118, 118, 118}, 3, 1.0); // the set stays: the relaxations' business
  EXPECT_EQ(cycle_period(s, is), 0);
  const auto [f, fi] = repeated({117, 117, 118, 118}, 2, 1.0); // two periods are not three
  EXPECT_EQ(cycle_period(f, fi), 0);
  // One iteration off the pattern within the last two periods.
  auto [o, oi] = repeated({117, 117, 118, 118}, 3, 1.0);
  o[o.size() - 3] = 116;
  EXPECT_EQ(cycle_period(o, oi), 0);
  EXPECT_EQ(cycle_period({}, {}), 0);
}

namespace
{
/// `n` increments from 1e-3 shrinking by `rate` each.
std::vector<double> geometric(int n, double rate)
{
  std::vector<double> increments;
  for (int i = 0; i < n; ++i)
    increments.push_back(1e-3 * std::pow(rate, i));
  return increments;
}
} // namespace

TEST(Stagnation, SteadyRateTooSlowForTheIterationsLeft)
{
  // At 0.983 from 1e-3 * 0.983^14 = 7.9e-4, 1e-10 takes 942 iterations.
  const std::vector<double> slow = geometric(15, 0.983);
  EXPECT_TRUE(stagnates(slow, 1e-10, 385));
  EXPECT_FALSE(stagnates(slow, 1e-10, 1000)); // within the iterations left
  EXPECT_FALSE(stagnates(slow, 1e-3, 385));   // converged already
  // The split's alternating ratios at fault_reactivation's step 53 (0.9819, 0.9826).
  std::vector<double> alternating = slow;
  for (std::size_t i = 1; i < alternating.size(); ++i)
    alternating[i] = alternating[i - 1] * (i % 2 ? 0.9819 : 0.9826);
  EXPECT_TRUE(stagnates(alternating, 1e-10, 385));
}

TEST(Stagnation, NoneWhereTheRateIsFastUnsteadyOrEarly)
{
  EXPECT_FALSE(stagnates(geometric(15, 0.85), 1e-10, 2));     // below stagnant_rate
  EXPECT_FALSE(stagnates(geometric(first_judged - 1, 0.99), 1e-10, 50)); // too early
  EXPECT_FALSE(stagnates(geometric(15, 1.01), 1e-10, 50));    // growing: not a rate below 1
  EXPECT_FALSE(stagnates(geometric(15, 0.9999), 1e-10, 50));  // above slowest_rate: gamma near 1
  std::vector<double> unsteady = geometric(15, 0.97);
  unsteady[12] *= 0.9; // one ratio 0.873, the next 1.078
  EXPECT_FALSE(stagnates(unsteady, 1e-10, 50));
  EXPECT_FALSE(stagnates({}, 1e-10, 50));
}
