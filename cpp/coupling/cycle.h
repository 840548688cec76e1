// A coupling iteration that cycles: the contact set returning with a short
// period while the increments stop shrinking, as the split does at a pair's
// kink (docs/theory.md, "Flow in a fault"). Found, it ends the window at
// once (a retry, or the error) instead of at coupling.max_iterations.
// Twin: python_prototype/coupling/cycle.py.
#pragma once

#include <cstdint>
#include <span>

namespace biotcontact
{

/// The longest period a cycle is looked for with.
constexpr int longest_cycle = 4;

/// An increment below this fraction of the one a period before is shrinking.
constexpr double cycle_shrink = 0.9995;

/// @brief The period P (2 .. longest_cycle) of the cycle the last iterations
/// show, 0 when they show none; the smallest such P.
///
/// A cycle of period P: the active contact nodes of the last 3P iterations
/// repeat with period P and change within it, and no increment of the last
/// 2P iterations is below cycle_shrink times the one P iterations before.
/// `active_nodes` and `increments` hold one entry per iteration, the last
/// iteration's last (the same on every rank).
int cycle_period(std::span<const std::int64_t> active_nodes, std::span<const double> increments);

} // namespace biotcontact
