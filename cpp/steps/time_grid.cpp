#include "steps/time_grid.h"

#include <sstream>

namespace biotcontact
{

TimeGrid time_grid(const Scene& scene)
{
  TimeGrid g;
  g.t = scene.times();
  for (std::size_t k = 0; k + 1 < g.t.size(); ++k)
    g.dt.push_back(scene.growth == 1.0 ? scene.dt : g.t[k + 1] - g.t[k]);
  return g;
}

void halve_steps(TimeGrid& grid, int first, int count)
{
  std::vector<double> t(grid.t.begin(), grid.t.begin() + first + 1), dt(grid.dt.begin(), grid.dt.begin() + first);
  for (int k = first; k < first + count; ++k)
  {
    const double half = grid.dt[k] / 2;
    t.push_back(grid.t[k] + half);
    t.push_back(grid.t[k + 1]);
    dt.insert(dt.end(), {half, half});
  }
  t.insert(t.end(), grid.t.begin() + first + count + 1, grid.t.end());
  dt.insert(dt.end(), grid.dt.begin() + first + count, grid.dt.end());
  grid.t = std::move(t);
  grid.dt = std::move(dt);
}

std::optional<std::string> retry_step(const Scene& scene, const std::string& cause, int step, int& attempts,
                                      TimeGrid& grid, int first, int count, long& retries)
{
  if (attempts >= scene.retry)
    return std::nullopt;
  ++attempts;
  ++retries;
  halve_steps(grid, first, count);
  std::ostringstream message;
  message << "step " << step << " failed (" << cause << "); retry " << attempts << " of " << scene.retry
          << " with dt = " << grid.dt[first];
  return message.str();
}

} // namespace biotcontact
