// Unit tests of the time grid (cpp/time/time_grid.h) and the scene's
// times (Scene::times, stops, is_output_time): fixed steps kept exactly,
// geometric growth ending on time.end, halving exact in binary floating
// point, time.retry counted and refused after the allowed attempts, and
// planned steps equal between stops and landing on every one. The
// prototype's twin is tests/unit/test_time_grid.py.
#include "time/time_grid.h"

#include <algorithm>
#include <cmath>
#include <gtest/gtest.h>

using namespace biotcontact;

namespace
{
Scene timed(double end, double dt, double growth = 1.0)
{
  Scene s;
  s.end_time = end;
  s.dt = dt;
  s.growth = growth;
  return s;
}

/// t increases strictly, and each dt is its step to round-off.
void expect_consistent(const TimeGrid& g)
{
  ASSERT_EQ(g.t.size(), g.dt.size() + 1);
  EXPECT_EQ(g.t.front(), 0.0);
  for (int k = 0; k < g.steps(); ++k)
  {
    EXPECT_GT(g.t[k + 1], g.t[k]) << "step " << k;
    EXPECT_NEAR(g.t[k + 1] - g.t[k], g.dt[k], 1e-14 * g.t.back()) << "step " << k;
  }
}
} // namespace

TEST(TimeGrid, FixedStepsAreWholeMultiplesKeptExactly)
{
  // 0.3 / 0.1 is 2.9999999999999996 in binary: still 3 steps, and each
  // step is dt itself, whatever the round-off of the times' differences.
  const Scene s = timed(0.3, 0.1);
  const TimeGrid g = time_grid(s);
  ASSERT_EQ(g.steps(), 3);
  EXPECT_EQ(s.num_steps(), 3);
  for (int k = 0; k < g.steps(); ++k)
  {
    EXPECT_EQ(g.dt[k], 0.1) << "step " << k;
    EXPECT_EQ(g.t[k + 1], (k + 1) * 0.1) << "time " << k + 1;
  }
  expect_consistent(g);
}

TEST(TimeGrid, GrowthIsGeometricAndEndsOnTheEnd)
{
  // dt_k = dt growth^k until time.end: dt (1.5^N - 1) / 0.5 >= 2 first at
  // N = ceil(log 11 / log 1.5) = 6, the last step cut short to land on 2.
  const Scene s = timed(2.0, 0.1, 1.5);
  const TimeGrid g = time_grid(s);
  const int N = static_cast<int>(std::ceil(std::log(11.0) / std::log(1.5)));
  ASSERT_EQ(g.steps(), N);
  EXPECT_EQ(s.num_steps(), N);
  EXPECT_EQ(g.t.back(), 2.0);
  for (int k = 0; k + 1 < N; ++k)
    EXPECT_NEAR(g.dt[k], 0.1 * std::pow(1.5, k), 1e-14 * s.end_time) << "step " << k;
  EXPECT_LE(g.dt.back(), 0.1 * std::pow(1.5, N - 1));
  expect_consistent(g);
}

TEST(TimeGrid, HalveStepsIsExact)
{
  // Halving steps 1 and 2 of five steps of 0.1: seven steps, the halves
  // exactly dt/2 and summing back to dt, the other times unchanged.
  TimeGrid g = time_grid(timed(0.5, 0.1));
  const TimeGrid before = g;
  halve_steps(g, 1, 2);
  ASSERT_EQ(g.steps(), 7);
  const std::vector<double> dt{0.1, 0.05, 0.05, 0.05, 0.05, 0.1, 0.1};
  for (int k = 0; k < 7; ++k)
    EXPECT_EQ(g.dt[k], dt[k]) << "step " << k;
  EXPECT_EQ(g.dt[1] + g.dt[2], before.dt[1]);
  EXPECT_EQ(g.t[2], before.t[1] + before.dt[1] / 2);
  for (auto [now, then] : {std::pair{0, 0}, {1, 1}, {3, 2}, {5, 3}, {6, 4}, {7, 5}})
    EXPECT_EQ(g.t[now], before.t[then]) << "time " << then << " kept";
  expect_consistent(g);
}

TEST(TimeGrid, RetryIsCountedAndRefusedAfterTheAllowedAttempts)
{
  Scene s = timed(1.0, 0.25);
  s.retry = 2;
  TimeGrid g = time_grid(s);
  int attempts = 0;
  long retries = 0;
  const auto first = retry_step(s, {3, "the coupling did not converge", 2, 1}, attempts, retries, g);
  ASSERT_TRUE(first);
  EXPECT_NE(first->find("step 3"), std::string::npos) << *first;
  EXPECT_NE(first->find("the coupling did not converge"), std::string::npos) << *first;
  EXPECT_NE(first->find("retry 1 of 2"), std::string::npos) << *first;
  EXPECT_EQ(attempts, 1);
  EXPECT_EQ(retries, 1);
  EXPECT_EQ(g.steps(), 5);
  EXPECT_EQ(g.dt[2], 0.125);

  const auto second = retry_step(s, {3, "the coupling did not converge", 2, 2}, attempts, retries, g);
  ASSERT_TRUE(second);
  EXPECT_NE(second->find("retry 2 of 2"), std::string::npos) << *second;
  EXPECT_EQ(g.steps(), 7);
  EXPECT_EQ(g.dt[2], 0.0625);

  const TimeGrid kept = g;
  EXPECT_FALSE(retry_step(s, {3, "the coupling did not converge", 2, 4}, attempts, retries, g));
  EXPECT_EQ(attempts, 2);
  EXPECT_EQ(retries, 2);
  EXPECT_EQ(g.t, kept.t) << "a refused retry leaves the grid";
}

TEST(TimeGrid, NoRetryWithoutTimeRetry)
{
  const Scene s = timed(1.0, 0.25);
  TimeGrid g = time_grid(s);
  int attempts = 0;
  long retries = 0;
  EXPECT_FALSE(retry_step(s, {1, "a solver failed", 0, 1}, attempts, retries, g));
  EXPECT_EQ(attempts, 0);
  EXPECT_EQ(retries, 0);
  EXPECT_EQ(g.steps(), 4);
}

TEST(TimeGrid, PlannedStepsLandOnEveryStop)
{
  // n = ceil((stop - t) / h) equal steps to each stop: 3 to 0.25, 4 to
  // 0.6, 4 to 1 with h = 0.1, none longer than h, each stop hit exactly.
  TimeGrid g{{0.0}, {}};
  const std::vector<double> stops{0.25, 0.6, 1.0};
  plan_steps(g, 0, 0.1, stops);
  ASSERT_EQ(g.steps(), 11);
  const std::vector<int> last{3, 7, 11}; // the index of each stop in t
  for (std::size_t j = 0; j < stops.size(); ++j)
  {
    EXPECT_EQ(g.t[last[j]], stops[j]) << "stop " << stops[j];
    const int begin = j == 0 ? 0 : last[j - 1];
    for (int k = begin; k < last[j]; ++k)
    {
      EXPECT_EQ(g.dt[k], g.dt[begin]) << "equal steps to " << stops[j];
      EXPECT_LE(g.dt[k], 0.1);
    }
  }
  expect_consistent(g);
}

TEST(TimeGrid, PlanningKeepsThePast)
{
  // Replanning after t_3 = 0.3 with h = 0.25: stop 0.2 is behind, one
  // step of 0.2 to 0.5, then two of 0.25 to 1.
  TimeGrid g = time_grid(timed(1.0, 0.1));
  const TimeGrid before = g;
  plan_steps(g, 3, 0.25, {0.2, 0.5, 1.0});
  ASSERT_EQ(g.steps(), 6);
  for (int k = 0; k <= 3; ++k)
    EXPECT_EQ(g.t[k], before.t[k]) << "time " << k;
  EXPECT_EQ(g.t[4], 0.5);
  EXPECT_EQ(g.t[6], 1.0);
  EXPECT_EQ(g.dt[4], 0.25);
  EXPECT_EQ(g.dt[5], 0.25);
  expect_consistent(g);
}

TEST(TimeGrid, WholeStepsPlannedWithoutASliver)
{
  // 2.1 / 0.3 is 7.000000000000001 in binary: 7 steps of 0.3, not 8.
  TimeGrid g{{0.0}, {}};
  plan_steps(g, 0, 0.3, {2.1});
  EXPECT_EQ(g.steps(), 7);
  EXPECT_EQ(g.t.back(), 2.1);
  EXPECT_NEAR(g.dt.front(), 0.3, 1e-15);
}

TEST(TimeGrid, AdaptiveGridLandsOnTheOutputTimes)
{
  // time.adaptive: steps of at most time.dt planned to every output time
  // and time.end (output_times holds time.end, as read_scene makes it).
  Scene s = timed(1.0, 0.2);
  s.adaptive = AdaptiveSpec{1e-3, 1e-6, 1.0};
  s.output_times = {0.3, 0.5, 1.0};
  EXPECT_EQ(s.stops(), s.output_times);
  const TimeGrid g = time_grid(s);
  for (double stop : s.output_times)
    EXPECT_NE(std::find(g.t.begin(), g.t.end(), stop), g.t.end()) << "stop " << stop;
  for (double dt : g.dt)
    EXPECT_LE(dt, 0.2);
  expect_consistent(g);
}

TEST(TimeGrid, StopsAndOutputTimes)
{
  Scene s = timed(1.0, 0.1);
  EXPECT_EQ(s.stops(), std::vector<double>{1.0}) << "no output times: time.end alone";
  EXPECT_TRUE(s.is_output_time(0.1)) << "no output times: every step is written";
  s.output_times = {0.5, 1.0};
  EXPECT_TRUE(s.is_output_time(0.5 + 1e-12)) << "within 1e-9 time.end";
  EXPECT_FALSE(s.is_output_time(0.5 + 1e-6));
  EXPECT_FALSE(s.is_output_time(0.7));
  EXPECT_TRUE(s.is_output_time(time_grid(s).t.back()));
}
