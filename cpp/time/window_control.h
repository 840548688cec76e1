// coupling.q = "auto": the number q of flow (fine) steps of each multirate
// window, chosen before the window from the predicted change of the
// mechanics over it (docs/theory.md, "Multirate with q = auto").
#pragma once

#include "time/time_grid.h"

#include <vector>

namespace biotcontact
{

/// @brief The q of the window that starts at fine step j of `grid`.
///
/// The flow keeps its step dt; the mechanics, solved once per window, is
/// lagged (and interpolated along the window's path) over H = q dt. Its
/// change over the next window is predicted from the last one's,
///   ||u(t_K + H) - u_K|| / u_size ~ H * rate,
///   rate = ||u_K - u_{K-1}|| / (u_size H_1),
/// and q is the largest whose predicted change stays within `tolerance`,
/// at most `limit` (coupling.q_max, lowered after a change of the contact
/// set: window_limit), over fine steps of one dt (a window's fine steps
/// share one matrix) and not past the next of `stops` (output times and
/// time.end). At least 1.
int window_steps(const TimeGrid& grid, int j, int limit, double rate, double tolerance,
                 const std::vector<double>& stops);

/// The limit of the next window's q after a window of q fine steps: 1 if
/// the contact set changed in it (the change is resolved at the flow's
/// step), else twice q, at most q_max: the windows grow again step by step
/// once the contact set has settled.
int window_limit(int q, int q_max, bool contact_changed);

} // namespace biotcontact
