#include "time/window_control.h"

#include <algorithm>
#include <cmath>

namespace biotcontact
{

int window_steps(const TimeGrid& grid, int j, int limit, double rate, double tolerance,
                 const std::vector<double>& stops)
{
  const double dt = grid.dt[j], slack = 1e-9 * grid.t.back();
  const double next_stop = *std::upper_bound(stops.begin(), stops.end(), grid.t[j] + slack);
  if (rate > 0)
    limit = std::min(limit, static_cast<int>(std::min(1e9, std::floor(tolerance / (rate * dt)))));
  int q = 1;
  while (q < limit and j + q < grid.steps() and grid.dt[j + q] == dt and grid.t[j + q] < next_stop - slack)
    ++q;
  return q;
}

int window_limit(int q, int q_max, bool contact_changed) { return contact_changed ? 1 : std::min(q_max, 2 * q); }

} // namespace biotcontact
