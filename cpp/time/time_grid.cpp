#include "time/time_grid.h"

#include <algorithm>
#include <cmath>
#include <sstream>

namespace biotcontact
{

TimeGrid time_grid(const Scene& scene)
{
  TimeGrid g;
  if (scene.adaptive)
  {
    g.t = {0.0};
    plan_steps(g, 0, scene.dt, scene.stops());
    return g;
  }
  g.t = scene.times();
  for (std::size_t k = 0; k + 1 < g.t.size(); ++k)
    g.dt.push_back(scene.growth == 1.0 ? scene.dt : g.t[k + 1] - g.t[k]);
  return g;
}

void plan_steps(TimeGrid& grid, int k, double h, const std::vector<double>& stops)
{
  grid.t.resize(k + 1);
  grid.dt.resize(k);
  const double slack = 1e-12 * stops.back();
  for (double stop : stops)
  {
    const double t0 = grid.t.back();
    if (stop <= t0 + slack)
      continue;
    const long n = std::max(1L, static_cast<long>(std::ceil((stop - t0) / h - 1e-9)));
    const double step = (stop - t0) / n;
    for (long i = 1; i <= n; ++i)
    {
      grid.t.push_back(i == n ? stop : t0 + i * step);
      grid.dt.push_back(step);
    }
  }
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

std::optional<std::string> retry_step(const Scene& scene, const FailedStep& failed, int& attempts, long& retries,
                                      TimeGrid& grid)
{
  if (attempts >= scene.retry)
    return std::nullopt;
  ++attempts;
  ++retries;
  halve_steps(grid, failed.first, failed.count);
  std::ostringstream message;
  message << "step " << failed.step << " failed (" << failed.cause << "); retry " << attempts << " of "
          << scene.retry << " with dt = " << grid.dt[failed.first];
  return message.str();
}

} // namespace biotcontact
