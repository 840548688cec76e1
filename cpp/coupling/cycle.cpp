// The cycle and the stagnation of a coupling iteration (coupling/cycle.h).
#include "coupling/cycle.h"

#include <algorithm>
#include <cmath>

namespace biotcontact
{

int cycle_period(std::span<const std::int64_t> active_nodes, std::span<const double> increments)
{
  const std::size_t n = std::min(active_nodes.size(), increments.size());
  for (std::size_t P = 2; P <= longest_cycle; ++P)
  {
    if (n < 3 * P)
      return 0;
    bool periodic = true, shrinking = false, changes = false;
    for (std::size_t i = n - 2 * P; i < n; ++i)
    {
      periodic = periodic and active_nodes[i] == active_nodes[i - P];
      shrinking = shrinking or increments[i] < cycle_shrink * increments[i - P];
    }
    for (std::size_t i = n - P; i < n; ++i)
      changes = changes or active_nodes[i] != active_nodes[n - 1];
    if (periodic and changes and !shrinking)
      return static_cast<int>(P);
  }
  return 0;
}

bool stagnates(std::span<const double> increments, double tolerance, int left)
{
  const std::size_t n = increments.size();
  if (n < static_cast<std::size_t>(std::max(first_judged, steady_iterations + 1)) or !(increments[n - 1] > tolerance))
    return false;
  const double last = increments[n - 1] / increments[n - 2];
  double slowest = last;
  for (std::size_t i = n - steady_iterations; i < n; ++i)
  {
    const double r = increments[i] / increments[i - 1];
    if (!(r >= stagnant_rate and r <= slowest_rate and std::abs(r - last) <= steady_spread))
      return false;
    slowest = std::max(slowest, r);
  }
  // The iterations the slowest of the steady ratios needs: log(tol / e) / log(r).
  return std::log(tolerance / increments[n - 1]) / std::log(slowest) > left;
}

} // namespace biotcontact
