// Unit tests of a window's time history (cpp/coupling/window.h): the
// displacement's path across a window is the straight line under backward
// Euler, and under BDF2 the quadratic through u_{K-1}, u_K and u, exactly
// at every fine time of an unequal pair of windows; the first window takes
// u at once and the second of q > 1 keeps the straight line; a window's
// derivative is BDF2 only where the step before equals its fine step. The
// prototype's twin is tests/unit/test_window.py.
#include "coupling/window.h"

#include <array>
#include <cmath>
#include <gtest/gtest.h>

using namespace biotcontact;

namespace
{
/// Windows of 2 fine steps of 1 s, then 3 of 0.5 s, then 2 of 1 s:
/// t = 0, 1, 2, 2.5, 3, 3.5, 4.5, 5.5.
TimeGrid grid()
{
  TimeGrid g;
  g.dt = {1, 1, 0.5, 0.5, 0.5, 1, 1};
  g.t = {0};
  for (double dt : g.dt)
    g.t.push_back(g.t.back() + dt);
  return g;
}

Window window(int K, int j, int q)
{
  Window w;
  w.K = K, w.j = j, w.q = q;
  return w;
}

/// Two entries: a linear and a rough value, so an entry-wise error shows.
const std::vector<double> u_before{1.0, -2.0}, u_K{3.0, 0.5}, u{4.0, 7.0};

WindowHistory history(TimeScheme scheme, const TimeGrid& g, int j_before)
{
  WindowHistory h(scheme, g);
  h.u_K = u_K, h.u_before = u_before, h.j_before = j_before;
  return h;
}

/// The Lagrange quadratic through (t0, y0), (t1, y1), (t2, y2) at t.
double quadratic(double t, const std::array<double, 3>& x, const std::array<double, 3>& y)
{
  double value = 0;
  for (int a = 0; a < 3; ++a)
  {
    double l = 1;
    for (int b = 0; b < 3; ++b)
      if (b != a)
        l *= (t - x[b]) / (x[a] - x[b]);
    value += l * y[a];
  }
  return value;
}
} // namespace

TEST(WindowHistory, BackwardEulerPathIsTheStraightLine)
{
  const TimeGrid g = grid();
  const WindowHistory h = history(TimeScheme::backward_euler, g, 0);
  const Window w = window(1, 2, 3); // [2, 3.5]
  for (int m = 0; m <= 3; ++m)
    for (std::size_t i = 0; i < u.size(); ++i)
      EXPECT_NEAR(h.path(w, u, m)[i], u_K[i] + (g.t[2 + m] - 2.0) / 1.5 * (u[i] - u_K[i]), 1e-14) << m;
  EXPECT_EQ(h.path(w, u, 0), u_K);
  EXPECT_EQ(h.path(w, u, 3)[1], u[1]);
}

TEST(WindowHistory, Bdf2PathIsTheQuadraticThroughThreeWindowEnds)
{
  const TimeGrid g = grid();
  // The third window [3.5, 5.5] after [2, 3.5]: u_{K-1} at 2, u_K at 3.5.
  const WindowHistory h = history(TimeScheme::bdf2, g, 2);
  const Window w = window(2, 5, 2);
  for (int m = 0; m <= 2; ++m)
    for (std::size_t i = 0; i < u.size(); ++i)
      EXPECT_NEAR(h.path(w, u, m)[i], quadratic(g.t[5 + m], {2.0, 3.5, 5.5}, {u_before[i], u_K[i], u[i]}), 1e-13)
          << "m " << m << ", entry " << i;
}

TEST(WindowHistory, Bdf2StartsWithTheEndValueAndTheLine)
{
  const TimeGrid g = grid();
  const WindowHistory h = history(TimeScheme::bdf2, g, 0);
  // The first window: u_0 may be the state before a load at t = 0+.
  const Window first = window(0, 0, 2);
  EXPECT_EQ(h.path(first, u, 0), u_K);
  EXPECT_EQ(h.path(first, u, 1), u);
  // The second window of q > 1 keeps the straight line.
  const Window second = window(1, 2, 3);
  EXPECT_NEAR(h.path(second, u, 1)[1], u_K[1] + (0.5 / 1.5) * (u[1] - u_K[1]), 1e-14);
}

TEST(WindowHistory, Bdf2OnlyWhereTheStepBeforeEqualsTheFineStep)
{
  const TimeGrid g = grid();
  const WindowHistory h = history(TimeScheme::bdf2, g, 0);
  EXPECT_FALSE(h.derivative(0, 2).second_order()); // no step before
  EXPECT_TRUE(h.derivative(1, 1).second_order());   // 1 after 1
  EXPECT_FALSE(h.derivative(2, 3).second_order());  // q = 3 of 0.5 after 1
  EXPECT_TRUE(h.derivative(2, 1).second_order());   // q = 1: variable-step BDF2
  EXPECT_FALSE(h.derivative(5, 2).second_order());  // 1 after 0.5, q = 2
  EXPECT_FALSE(history(TimeScheme::backward_euler, g, 0).derivative(1, 1).second_order());
}
