#include "scene/schema.h"

#include <algorithm>
#include <cmath>

namespace biotcontact
{

std::vector<std::string> builtin_boundary_names(int dimension)
{
  if (dimension == 2)
    return {"left", "right", "bottom", "top"};
  return {"left", "right", "front", "back", "bottom", "top"};
}

bool Scene::cellwise_body_force() const
{
  return std::any_of(regions.begin(), regions.end(), [](const auto& entry) { return entry.second.body_force; });
}

bool Scene::has_contact() const
{
  for (const auto& [name, b] : boundaries)
    if (b.contact)
      return true;
  return !faults.empty();
}

std::vector<double> Scene::times() const
{
  std::vector<double> t = {0.0};
  if (growth == 1.0)
  {
    // Whole multiples of dt, so that every scheme writes the same times.
    const long n = std::llround(end_time / dt);
    for (long k = 1; k <= n; ++k)
      t.push_back(k * dt);
    return t;
  }
  // dt_k = dt growth^(k-1); the last step ends at time.end.
  double step = dt;
  // Stops one past the limit, which read_scene then refuses.
  while (t.back() < end_time * (1 - 1e-12) and t.size() <= static_cast<std::size_t>(max_steps) + 1)
  {
    t.push_back(std::min(t.back() + step, end_time));
    step *= growth;
  }
  return t;
}

int Scene::num_steps() const
{
  if (growth == 1.0)
    return static_cast<int>(std::llround(end_time / dt));
  return static_cast<int>(times().size()) - 1;
}

std::vector<double> Scene::stops() const
{
  return output_times.empty() ? std::vector<double>{end_time} : output_times;
}

bool Scene::is_output_time(double t) const
{
  if (output_times.empty())
    return true;
  const auto k = std::lower_bound(output_times.begin(), output_times.end(), t - 1e-9 * end_time);
  return k != output_times.end() and std::abs(*k - t) <= 1e-9 * end_time;
}

} // namespace biotcontact
