// The second flow pass of the scheme "multirate-two-pass"
// (docs/multirate-two-pass.md): after the mechanics, the window's fine flow
// steps again without L and with the new displacement, replacing the fine
// pressures the mechanics cannot see. Twin:
// python_prototype/coupling/two_pass.py.
#pragma once

#include "coupling/window.h"
#include "steps/flow_step.h"

namespace biotcontact
{

/// The printed multirate scheme damps the fine-step pressure modes that sum to zero
/// over the window only by L/(S+L) ~ gamma per iteration: the mechanics
/// sees p^q alone. Here the fine steps are recomputed without L, from p_K
/// and with the new displacement u^{n+1}:
///   (S (p^B_m - p^B_{m-1})/dt, th) + (div z^B_m, th)
///     = (Q(t_m), th) - ((alpha/q) div(u^{n+1} - u_K)/dt, th),
/// so they hold no error of their own, only that of u^{n+1}; the window end
/// keeps the first pass's value p^A_q (the one the mechanics used) through
///   p^{n+1,m} = p^B_m + (m/q)(p^A_q - p^B_q),   m = 1..q,
/// the same linear correction applied to the mixed states (z, p). At the
/// fixed point p^B = p^A: the fixed point is that of the printed scheme.
/// `second` solves without L; `flow` is the first pass's step.
void second_pass_correction(FlowStep& second, FlowStep& flow, Window& w, const WindowHistory& history);

} // namespace biotcontact
