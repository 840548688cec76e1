// Unit tests of a coupling iteration's cycle (cpp/coupling/cycle.h): a
// contact set returning every P iterations with increments that do not
// shrink is a cycle of period P, the smallest; a set that stays, increments
// that shrink by more than 0.05 % a period, or too few iterations are none.
// The prototype's twin is tests/unit/test_cycle.py.
#include "coupling/cycle.h"

#include <gtest/gtest.h>
#include <vector>

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
