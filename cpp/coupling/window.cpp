#include "coupling/window.h"

#include "assembly/linear_algebra.h"

#include <algorithm>
#include <cmath>
#include <sstream>

namespace biotcontact
{

std::string not_converged_message(const Window& w, const WindowFailure& failure)
{
  std::ostringstream message;
  if (w.cycle)
  {
    message << "the fixed-stress split cycles at t = " << failure.t << " (step " << w.K + 1 << "): after "
            << w.pinned_at + w.increments.size() << " iterations the contact set returns every " << w.cycle
            << " iterations (active nodes";
    for (std::size_t i = w.active_nodes.size() - w.cycle; i < w.active_nodes.size(); ++i)
      message << " " << w.active_nodes[i];
    message << ") and the increments no longer shrink" << (w.pin_rounds != 0 ? ", pinned or not" : "")
            << "; last increments:";
  }
  else
    message << "the fixed-stress split did not converge in " << failure.max_iterations << " iterations at t = "
            << failure.t << " (step " << w.K + 1 << "); last increments:";
  for (std::size_t i = w.log.size() > 3 ? w.log.size() - 3 : 0; i < w.log.size(); ++i)
    message << w.log[i];
  message << " " << failure.advice;
  // A step at the threshold of an opening or a contact change can keep the
  // split cycling where half the step passes (docs/theory.md, "Flow in a
  // fault": the split through an opening).
  if (failure.propose_retry)
    message << ", time.retry = 4 (a failed step again with half its dt, up to 4 times)";
  return message.str();
}

void WindowHistory::start(const FlowStep& flow, std::span<const double> u, int j_previous)
{
  p_K = values(flow.pressure->x()->array());
  u_K = values(u);
  p_before = values(flow.p_before->x()->array());
  u_before = values(flow.u_before->x()->array());
  u_path_before = values(flow.u_path_before->x()->array());
  j_before = j_previous;
}

/// The time derivative of a window's fine steps (j the first, q of them):
/// time.scheme's, from the steps before (time_scheme.h). With q > 1 every
/// fine step of a window shares one matrix, so BDF2 needs the step before
/// the window to equal the window's fine step (w = 1); the first window,
/// and one whose fine step a retry halved, take backward Euler, which keeps
/// the global error second order (a bounded number of first-order steps,
/// each O(dt^2)).
TimeDerivative WindowHistory::derivative(int j, int q) const
{
  const double dt = grid.dt[j], previous = j > 0 ? grid.dt[j - 1] : 0.0;
  if (q > 1 and previous != dt)
    return {};
  return time_derivative(scheme, dt, previous);
}

/// The displacement of window w at its fine time m (m = 0..q) along the
/// window's path from u_K to u = u(t_{K+1}). Backward Euler: the paper's
/// straight line. BDF2: the quadratic through u_{K-1}, u_K, u
///   Q(t_K + s) = u_K + s D1 + s (s - H) D2,  D1 = (u - u_K)/H,
///   D2 = ((u - u_K)/H - (u_K - u_{K-1})/H1) / (H + H1),
/// H and H1 the window's and the previous window's lengths: the straight
/// line (D2 = 0) makes the flow's displacement term first order in H
/// whatever the time scheme, the quadratic keeps it second order. The
/// first window has no u_{K-1}, and u_0 may be the state before a load
/// applied at t = 0+: there u takes its end value at the first fine step
/// (the undrained response at once; the straight line would spread a jump
/// over the window and drain too little, an O(H) error), and with q > 1 the
/// second window, whose u_{K-1} is u_0, keeps the straight line
/// (docs/theory.md, "Time schemes").
std::vector<double> WindowHistory::path(const Window& w, const std::vector<double>& u, int m) const
{
  const bool bdf2 = scheme == TimeScheme::bdf2;
  if (bdf2 and w.K == 0)
    return m == 0 ? u_K : u;
  const double H = t(w, w.q) - t(w, 0), s = t(w, m) - t(w, 0);
  const bool quadratic = bdf2 and (w.q == 1 or w.K > 1);
  const double H1 = quadratic ? t(w, 0) - grid.t[j_before] : 1.0;
  std::vector<double> Q(u.size());
  for (std::size_t i = 0; i < u.size(); ++i)
  {
    const double D1 = (u[i] - u_K[i]) / H;
    const double D2 = quadratic ? (D1 - (u_K[i] - u_before[i]) / H1) / (H + H1) : 0.0;
    Q[i] = u_K[i] + s * D1 + s * (s - H) * D2;
  }
  return Q;
}

/// The time history of fine step m of `flow` from the pressures p[0..m-1]
/// (p[0] = p_K) and the window's displacement u. Backward Euler: p[m-1] and
/// u_K (the paper's scheme). BDF2 differentiates the fluid content
/// S p + alpha div u at the fine times with the window's derivative (BDF2,
/// or backward Euler where it starts), p from its fine steps and u along
/// the window's path:
///   p* = (c1 p[m-1] - c2 p[m-2]) / c0,
///   alpha div(u - u_window) / (q dt / c0)
///     = alpha div (c0 Q(t_m) - c1 Q(t_{m-1}) + c2 Q(t_{m-2})) / dt,
/// i.e. u_window = u - q (Q(t_m) - Q*), where the values one fine step
/// before t_K (p[-1], Q(t_{-1})) are those of the previous window.
void WindowHistory::set_time_history(FlowStep& flow, const Window& w, int m,
                                     const std::vector<std::vector<double>>& p, const std::vector<double>& u) const
{
  if (scheme != TimeScheme::bdf2)
  {
    assign(*flow.p_previous, p[m - 1]);
    return;
  }
  assign(*flow.p_previous, previous(w, p, m));
  const std::vector<double> Q = path(w, u, m);
  const std::vector<double> Q_star
      = history_value(w.derivative, path(w, u, m - 1), m >= 2 ? path(w, u, m - 2) : u_path_before);
  std::span<double> window = flow.u_window->x()->mutable_array();
  for (std::size_t i = 0; i < Q.size(); ++i)
    window[i] = u[i] - w.q * (Q[i] - Q_star[i]);
}

std::vector<double> WindowHistory::previous(const Window& w, const std::vector<std::vector<double>>& p, int m) const
{
  return history_value(w.derivative, p[m - 1], m >= 2 ? p[m - 2] : p_before);
}

void WindowHistory::accept(const Window& w, FlowStep& flow)
{
  p_before = w.p_new[w.q - 1]; // p_K itself for q = 1
  u_path_before = path(w, w.u_new, w.q - 1);
  u_before = u_K;
  j_before = w.j;
  assign(*flow.p_before, p_before);
  assign(*flow.u_before, u_before);
  assign(*flow.u_path_before, u_path_before);
  p_K = w.p_new[w.q];
  u_K = w.u_new;
}

void accelerate_window(Window& w, MPI_Comm comm, int depth, const AndersonScales& scales)
{
  std::vector<std::int32_t> owned(w.q, scales.p_owned);
  owned.push_back(scales.u_owned);
  const double p_size = std::sqrt(static_cast<double>(w.q)) * scales.p_size;
  std::vector<double> weights(w.q, p_size > 0 ? 1 / p_size : 1.0);
  weights.push_back(scales.u_size > 0 ? 1 / scales.u_size : 1.0);
  w.anderson.emplace(comm, depth, owned, weights);
  w.accelerated = true;
}

void mix_iterates(Window& w)
{
  State x(w.p_old.begin() + 1, w.p_old.end()), g(w.p_new.begin() + 1, w.p_new.end());
  x.push_back(w.u_old);
  g.push_back(w.u_new);
  w.anderson->next(x, g);
  std::copy(x.begin(), x.begin() + w.q, w.p_old.begin() + 1);
  w.u_old = x.back();
}

std::vector<double> fault_reference(const Window& w, int m)
{
  if (m == 1) // p_f^{n,0} = p_f^{n+1,0}: the window's start
    return w.fault_old[1];
  std::vector<double> reference = difference(w.fault_old[m], w.fault_old[m - 1]);
  for (std::size_t i = 0; i < reference.size(); ++i)
    reference[i] += w.fault_new[m - 1][i];
  return reference;
}

std::string window_name(const Window& w, double t)
{
  std::ostringstream name;
  name << "step " << w.K + 1 << " (t = " << t << ")";
  return name.str();
}

std::string stagnation_note(const Window& w, double t, int left)
{
  const std::size_t n = w.increments.size();
  std::ostringstream message;
  message << window_name(w, t) << ": the split contracts by "
          << w.increments[n - 1] / w.increments[n - 2] << " per iteration, too slowly for the " << left
          << " iterations left; Anderson acceleration from iteration " << n + 1;
  return message.str();
}

} // namespace biotcontact
