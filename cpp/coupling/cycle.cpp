// The cycle of a coupling iteration (coupling/cycle.h).
#include "coupling/cycle.h"

#include <algorithm>

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

} // namespace biotcontact
