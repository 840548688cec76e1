// The times of a run, t_0 = 0 < t_1 < ... < t_N = time.end, and the step
// dt_k = t_{k+1} - t_k of each, kept exactly (dt from the scene, grown by
// time.growth, or planned by time.adaptive) so that a constant step is
// recognised as unchanged and its matrices are not rebuilt. A failed step
// retried with time.retry has its fine steps halved (dt/2 is exact in
// binary floating point); an adaptive run plans the steps after each
// accepted one again (time/step_control.h); a checkpoint keeps the
// grid, so that a restart continues on it.
#pragma once

#include "scene/scene.h"

#include <optional>
#include <string>
#include <vector>

namespace biotcontact
{

struct TimeGrid
{
  std::vector<double> t;  // N + 1 times
  std::vector<double> dt; // N steps
  int steps() const { return static_cast<int>(dt.size()); }
};

/// The scene's times (Scene::times) with their steps.
TimeGrid time_grid(const Scene& scene);

/// Replaces the steps after t_k by steps of about h that land on every stop
/// after t_k (Scene::stops): n = ceil((stop - t) / h) equal steps to each.
void plan_steps(TimeGrid& grid, int k, double h, const std::vector<double>& stops);

/// Halves the steps first, ..., first + count - 1 (count more steps).
void halve_steps(TimeGrid& grid, int first, int count);

/// @brief A step that failed: its number (for the message), why, and its
/// fine steps first, ..., first + count - 1 on the grid.
struct FailedStep
{
  int step;
  std::string cause;
  int first, count;
};

/// time.retry: whether a step that failed may be tried again with halved
/// steps (`attempts` retries of it so far, at most scene.retry); if so,
/// counts the retry in `attempts` and `retries` (the run's), halves the
/// failed fine steps of `grid` and returns the message that says so.
std::optional<std::string> retry_step(const Scene& scene, const FailedStep& failed, int& attempts, long& retries,
                                      TimeGrid& grid);

} // namespace biotcontact
