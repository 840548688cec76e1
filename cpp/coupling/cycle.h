// A coupling iteration that will not converge: one that cycles (the contact
// set returning with a short period while the increments stop shrinking, as
// the split does at a pair's kink), found, ends the window at once (a
// retry, or the error); one that stagnates (a steady rate near 1, as the
// split's over-stabilised mode of a fault's open patch) is handed to
// Anderson's method by coupling.acceleration = "auto" (docs/theory.md,
// "Flow in a fault"). Twin: python_prototype/coupling/cycle.py.
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

/// The iterations a steady rate is judged on, and the first iteration
/// judged: the start of a step's iteration may wander.
constexpr int steady_iterations = 5, first_judged = 10;

/// A steady rate: each of the last steady_iterations ratios of consecutive
/// increments lies in [stagnant_rate, slowest_rate] and within
/// steady_spread of the last. Above slowest_rate the increments no longer
/// bound the error (about r/(1 - r) times the last, 1000 times at 0.999):
/// gamma near 1, the monolithic scheme's case, where the split ends in its
/// error as before.
constexpr double stagnant_rate = 0.9, slowest_rate = 0.999, steady_spread = 0.02;

/// @brief Whether the iteration stagnates: from iteration first_judged on,
/// its increments shrink at a steady rate r (above) so slowly that at r the
/// last increment would not reach `tolerance` within `left` iterations.
///
/// `increments` holds one entry per iteration, the last iteration's last
/// (the same on every rank).
bool stagnates(std::span<const double> increments, double tolerance, int left);

} // namespace biotcontact
