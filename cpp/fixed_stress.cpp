#include "fixed_stress.h"

#include "anderson.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <sstream>

namespace biotcontact
{
using namespace dolfinx;

namespace
{
using Array = std::vector<double>;

Array copy(const fem::Function<double>& f)
{
  std::span<const double> x = f.x()->array();
  return Array(x.begin(), x.end());
}

void assign(fem::Function<double>& f, const Array& values)
{
  std::copy(values.begin(), values.end(), f.x()->mutable_array().begin());
}

Array difference(const Array& a, const Array& b)
{
  Array d(a.size());
  for (std::size_t i = 0; i < a.size(); ++i)
    d[i] = a[i] - b[i];
  return d;
}

/// Ratios measured below this fraction of a window's first ||delta sigma||
/// are at round-off level (see the loop).
constexpr double resolved_fraction = 1e-6;
constexpr double round_off_fraction = 1e-9;

/// increment / size, or the increment itself while size = 0.
double relative(double increment, double size) { return size > 0 ? increment / size : increment; }

/// Changes of the contact active set so far (0 without contact).
long contact_changes(MechanicsStep& mechanics)
{
  return mechanics.system().has_contact() ? mechanics.system().contact().active_set_changes : 0;
}

/// The second pass of "multirate-two-pass" (docs/multirate-two-pass.md). The printed
/// multirate scheme damps the fine-step pressure modes that sum to zero
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
void second_pass_correction(FlowStep& second, const Array& p_K, const Array& u_new,
                            const std::function<double(int)>& t, std::vector<Array>& p_new,
                            std::vector<Array>& w_new)
{
  const int q = static_cast<int>(p_new.size()) - 1;
  std::vector<Array> p_B(q + 1, p_K), w_B(q + 1);
  assign(*second.u_iterate, u_new);
  for (int m = 1; m <= q; ++m)
  {
    assign(*second.p_previous, p_B[m - 1]);
    second.solve(t(m));
    p_B[m] = copy(*second.pressure);
    std::span<const double> w = second.state();
    w_B[m].assign(w.begin(), w.end());
  }
  const Array p_end = difference(p_new[q], p_B[q]), w_end = difference(w_new[q], w_B[q]);
  for (int m = 1; m < q; ++m)
  {
    const double s = static_cast<double>(m) / q;
    for (std::size_t i = 0; i < p_end.size(); ++i)
      p_new[m][i] = p_B[m][i] + s * p_end[i];
    for (std::size_t i = 0; i < w_end.size(); ++i)
      w_new[m][i] = w_B[m][i] + s * w_end[i];
  }
}

} // namespace

double inexact_tolerance(double previous_increment)
{
  return std::clamp(1e-2 * previous_increment, iterative_tolerance, 1e-4);
}

void run_fixed_stress(const Scene& scene, const Parameters& P, const Constants& constants, FlowStep& flow,
                      FlowStep* second_pass, MechanicsStep& mechanics, ContractionNorm& contraction, Output& output,
                      const WindowObserver& observer, CouplingReport& report, TimeGrid& grid)
{
  const CouplingSpec& coupling = *scene.coupling;
  const int q = P.q;
  const bool multirate = coupling.multirate();
  const bool accelerated = coupling.acceleration == "anderson";
  const fem::FunctionSpace& V = *mechanics.space();
  const fem::FunctionSpace& Q = *flow.pressure_space();

  double& ratio_sum = report.ratio_sum;
  flow.keep_loads(q);
  if (second_pass)
    second_pass->keep_loads(q);

  // Converged state at t_K: (u_K, p_K).
  Array p_K = copy(*flow.pressure);
  Array u_K = copy(*mechanics.u);
  // The largest p (summed over the q fine steps) and u of the run so far:
  // the scales of the stopping test.
  double& p_size = report.p_size;
  double& u_size = report.u_size;
  if (report.windows == 0)
  {
    p_size = std::sqrt(static_cast<double>(q)) * owned_norm(p_K, Q);
    u_size = owned_norm(u_K, V);
  }

  int attempts = 0; // retries of the current window (time.retry)
  for (int K = report.windows; K < grid.steps() / q; ++K)
  {
    // Fine time m of the window (t_K + m dt for a constant step).
    auto t = [&](int m) { return grid.t[K * q + m]; };
    if (set_time_step(constants, grid.dt[K * q]))
    {
      flow.time_step_changed();
      if (second_pass)
        second_pass->time_step_changed();
    }
    const std::vector<double> w_K(flow.state().begin(), flow.state().end());
    // Start: p^{0,m} = p_K for all m, u^0 = u_K.
    std::vector<Array> p_old(q + 1, p_K), p_new(q + 1, p_K);
    std::vector<Array> w_new(q + 1);
    Array u_old = u_K, u_new;
    assign(*flow.u_window, u_K);
    if (second_pass)
      assign(*second_pass->u_window, u_K);
    // coupling.acceleration = "anderson": the iterate fed to the next pass
    // is a combination of the last map values (anderson.h); its state is
    // (p^1, ..., p^q, u), weighted by the scales of the stopping test.
    std::optional<AndersonAcceleration> anderson;
    long active_set_changes = contact_changes(mechanics);
    if (accelerated)
    {
      std::vector<std::int32_t> owned(q, owned_size(Q));
      owned.push_back(owned_size(V));
      std::vector<double> weights(q, p_size > 0 ? 1 / p_size : 1.0);
      weights.push_back(u_size > 0 ? 1 / u_size : 1.0);
      anderson.emplace(V.mesh()->comm(), coupling.depth, owned, weights);
    }
    double dsigma_previous = std::numeric_limits<double>::quiet_NaN(), dsigma_first = 0;
    bool converged = false;
    int n = 0;
    double increment = 1; // max(dp, du) of the last iteration
    std::vector<std::string> log; // the last iterations, for the error message
    // time.retry: back to the start of the window, whose fine steps are
    // halved (two windows of q steps); false when no retry is left.
    auto retry = [&](const std::string& cause)
    {
      const auto message = retry_step(scene, cause, K + 1, attempts, grid, K * q, q, report.retries);
      if (!message)
        return false;
      flow.set_state(w_K);
      assign(*mechanics.u, u_K);
      if (observer.retry)
        observer.retry(*message);
      --K;
      return true;
    };

    try
    {
      for (n = 0; n < coupling.max_iterations; ++n)
      {
        // (a) q flow steps with u^n lagged:
        //   ((S+L)(p^{n+1,m} - p^{n+1,m-1})/dt, th) + (div z^{n+1,m}, th)
        //     = (Q(t_m), th) + (L (p^{n,m} - p^{n,m-1})/dt, th)
        //       - ((alpha/q) div(u^n - u_K)/dt, th)
        if (scene.solver.inexact_coupling)
        {
          flow.system().set_tolerance(inexact_tolerance(increment));
          mechanics.system().set_tolerance(inexact_tolerance(increment));
        }
        assign(*flow.u_iterate, u_old);
        for (int m = 1; m <= q; ++m)
        {
          assign(*flow.p_previous, p_new[m - 1]);
          assign(*flow.p_iterate, p_old[m]);
          assign(*flow.p_iterate_previous, p_old[m - 1]);
          flow.solve(t(m));
          p_new[m] = copy(*flow.pressure);
          std::span<const double> w = flow.state();
          w_new[m].assign(w.begin(), w.end());
        }
        // (b) mechanics (the VI) at t_{K+1} with p = p^{n+1,q}: flow.pressure
        // holds it and is the pressure coefficient of the mechanics load.
        mechanics.solve(t(q));
        u_new = copy(*mechanics.u);
        // (c) "multirate-two-pass": the fine steps again, without L, with
        // u^{n+1}; for q = 1 the correction returns p^A_1 itself.
        if (second_pass and q > 1)
          second_pass_correction(*second_pass, p_K, u_new, t, p_new, w_new);

        // Contraction quantities, measured on the increments of this iteration.
        const Array du = difference(u_new, u_old);
        double dsigma = 0, theorem2 = 0, dp2 = 0, p2 = 0;
        Array dp_previous(p_K.size(), 0.0);
        for (int m = 1; m <= q; ++m)
        {
          const Array dp = difference(p_new[m], p_old[m]);
          // Theorem 2: delta sigma^{n+1,m} = (dp^m - dp^{m-1}) - alpha/(qL) div du
          if (P.L > 0)
          {
            const double t2 = contraction(P.alpha / (q * P.L), du, 1.0, difference(dp, dp_previous));
            theorem2 += t2 * t2;
          }
          dp_previous = dp;
          const double dpn = owned_norm(dp, Q), pn = owned_norm(p_new[m], Q);
          dp2 += dpn * dpn;
          p2 += pn * pn;
        }
        theorem2 = P.L > 0 ? std::sqrt(theorem2) : std::numeric_limits<double>::quiet_NaN();
        if (multirate)
          dsigma = theorem2;
        else
          // Theorem 1: delta sigma_v^{n+1} = lambda div(du) - alpha dp
          dsigma = contraction(P.lambda, du, P.alpha, difference(p_new[1], p_old[1]));

        const double ratio = n > 0 ? dsigma / dsigma_previous : std::numeric_limits<double>::quiet_NaN();
        if (n == 0)
          dsigma_first = dsigma;
        // A ratio is held against gamma from the second one on, while the
        // increments are resolved:
        // - the first ratio compares with delta sigma^1 = sigma^1 - sigma^0,
        //   and u^0 = u_K is no mechanics solution at this step's loads, which
        //   the proof of Theorem 1 needs for both iterates it subtracts;
        // - once ||delta sigma|| has fallen six orders below the window's
        //   first one, or below 1e-9 of the norm of the quantity itself, it is
        //   made of the round-off of the solves (the displacement carries
        //   ~1e-11 relative round-off, amplified by div).
        // The other ratios are logged and counted as unresolved.
        const double size = multirate ? contraction(P.alpha / (q * P.L), u_new, 1.0, p_new[q])
                                      : contraction(P.lambda, u_new, P.alpha, p_new[1]);
        // With acceleration the iterates are no longer x^{n+1} = G(x^n), so
        // the ratios are logged but not held against gamma.
        const bool resolved = !accelerated and n > 1 and dsigma >= resolved_fraction * dsigma_first
                              and dsigma >= round_off_fraction * size;
        if (n > 0 and !resolved)
          ++report.unresolved_ratios;
        if (resolved and std::isfinite(ratio))
        {
          report.max_contraction_ratio = std::max(report.max_contraction_ratio, ratio);
          ratio_sum += ratio;
          ++report.ratios;
          if (ratio > P.gamma)
            ++report.bound_violations;
        }
        dsigma_previous = dsigma;

        // Stopping test on the increments of this iteration (never on a stale
        // state): l2 norms of the p and u increments relative to the largest p
        // and u of the run so far (relative to the current iterate alone, a
        // field decaying to zero, e.g. p at steady state, would be judged by
        // its round-off).
        p_size = std::max(p_size, std::sqrt(p2));
        u_size = std::max(u_size, owned_norm(u_new, V));
        const double dp_norm = relative(std::sqrt(dp2), p_size);
        const double du_norm = relative(owned_norm(du, V), u_size);
        output.iteration({K + 1, t(q), n + 1, dsigma, ratio, P.gamma, dp_norm, du_norm,
                          mechanics.active_contact_nodes()});
        if (!std::isfinite(p2) or !std::isfinite(u_size))
          // The iterates hold NaN or inf (a load or coefficient that is not
          // finite): no further iteration can recover.
          throw SolverError("non-finite values (NaN or inf) in the "
                            + std::string(std::isfinite(p2) ? "displacement" : "pressure"));
        std::ostringstream entry;
        entry << " " << n + 1 << ": dp " << dp_norm << " du " << du_norm << " dsigma " << dsigma << ";";
        log.push_back(entry.str());

        if (anderson)
        {
          // The differences of earlier iterations describe the map of their
          // contact active set only: a new set restarts the history.
          if (const long changes = contact_changes(mechanics); changes != active_set_changes)
          {
            anderson->restart();
            active_set_changes = changes;
          }
          State x(p_old.begin() + 1, p_old.end()), g(p_new.begin() + 1, p_new.end());
          x.push_back(u_old);
          g.push_back(u_new);
          anderson->next(x, g);
          std::copy(x.begin(), x.begin() + q, p_old.begin() + 1);
          u_old = x.back();
        }
        else
        {
          p_old = p_new;
          u_old = u_new;
        }
        increment = std::max(dp_norm, du_norm);
        if (dp_norm <= coupling.tolerance and du_norm <= coupling.tolerance)
        {
          converged = true;
          // Coupled residual of the accepted state: the flow equations with
          // u^{n+1} in place of u^n differ by L(dp^m - dp^{m-1}) - (alpha/q) div du
          // = L delta sigma^{n+1,m}; relative to the fluid content change.
          if (P.L > 0)
          {
            const double change = contraction(P.alpha, difference(u_new, u_K), -P.storage,
                                              difference(p_new[q], p_K));
            report.max_coupled_residual = std::max(
                report.max_coupled_residual, change > 0 ? P.L * theorem2 / change : 0.0);
          }
          break;
        }
      }
    }
    catch (const SolverError& e)
    {
      // The failing solve named its system; the iteration is known here.
      const std::string cause = "coupling iteration " + std::to_string(n + 1) + ": " + e.what();
      if (!retry(cause))
        throw SolverError(cause);
      continue;
    }
    report.coupling_iterations += std::min(n + 1, coupling.max_iterations);
    report.max_iterations_per_step = std::max(report.max_iterations_per_step, std::min(n + 1, coupling.max_iterations));
    if (!converged)
    {
      std::ostringstream message;
      message << "the fixed-stress split did not converge in " << coupling.max_iterations
              << " iterations at t = " << t(q) << " (step " << K + 1
              << "); last increments:";
      for (std::size_t i = log.size() > 3 ? log.size() - 3 : 0; i < log.size(); ++i)
        message << log[i];
      if (retry("the fixed-stress split did not converge"))
        continue;
      report.converged = false;
      report.mean_contraction_ratio = report.ratios ? ratio_sum / report.ratios : 0.0;
      throw CouplingError(message.str());
    }
    attempts = 0;

    // Accept the window: write every fine flow step, then the mechanics step.
    for (int m = 1; m <= q; ++m)
    {
      flow.set_state(w_new[m]);
      observer.flow_state(t(m));
    }
    observer.mechanics_state(t(q), K + 1, n + 1);
    report.windows = K + 1;
    p_K = p_new[q];
    u_K = u_new;
    if (observer.stop and observer.stop())
      break;
  }
  report.mean_contraction_ratio = report.ratios ? ratio_sum / report.ratios : 0.0;
}

} // namespace biotcontact
