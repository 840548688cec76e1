// time.adaptive: the time step chosen from a local error estimate
// (docs/theory.md "Adaptive steps" derives it and measures the choices).
//
// After a step from t_{n-1} to t_n = t_{n-1} + h (solution y_n, for the
// pressure and for the displacement) Milne's device estimates the local
// error LTE from y_n minus the polynomial P through the last accepted states
// (StepControl::estimate), per unit step, relative to the time reached and
// to the field's largest norm so far:
//   est = max over fields ||LTE|| / ||y||_max * (t_n / h) / tolerance.
// A step with est <= 1 is accepted and Gustafsson's PI controller steers est
// to 1/2; one above is tried again, shorter (StepControl::judge). The
// predictor does not reach back across t = 0 or a change of the contact set.
#pragma once

#include "scene/scene.h"
#include "time/time_grid.h"

#include <dolfinx/fem/Function.h>
#include <memory>
#include <span>
#include <string>
#include <vector>

namespace biotcontact
{

/// @brief What time.adaptive reports (summary.json): the steps tried
/// again, shorter, for their error estimate; those accepted at dt_min above
/// the tolerance; the largest estimate of an accepted step (1: the
/// tolerance); the steps accepted unestimated because the active contact
/// set changed in them.
struct AdaptiveReport
{
  long rejected_steps = 0, forced_steps = 0;
  double max_error_estimate = 0;
  long contact_breaks = 0;
};

/// @brief The PI controller's memory (checkpointed, as are the states of
/// history(): a restart continues the same steps): the last accepted
/// step's estimate, the largest norms of pressure and displacement so far,
/// and the accepted states since t = 0 or the last contact break (the
/// predictor's reach).
struct AdaptiveState
{
  double error_estimate = 0, p_largest = 0, u_largest = 0;
  long smooth_states = 0;
};

/// @brief A step to judge: the one ending at grid.t[k] with solution (p, u)
/// (either may be empty); `smooth` is false when the active contact set
/// changed in it.
struct StepSolution
{
  int k;
  std::span<const double> p, u;
  bool smooth;
};

/// @brief The error estimate and PI controller of time.adaptive, for the
/// pressure in Q and the displacement in V (either may be absent).
class StepControl
{
public:
  StepControl(const Scene& scene, std::shared_ptr<const dolfinx::fem::FunctionSpace> Q,
              std::shared_ptr<const dolfinx::fem::FunctionSpace> V);

  /// The norms of the state at t = 0 (the fields' scales start there).
  void start(std::span<const double> p, std::span<const double> u, AdaptiveState& state);

  /// Judges `step` on `grid`: accepted, it is remembered and the steps
  /// after t_k are planned again; rejected, the steps from t_{k-1} on are,
  /// shorter, and the message says so. A step with est <= 1 is accepted;
  /// the next step comes from Gustafsson's PI controller steering est to
  /// the set point 1/2,
  ///   h' = h b (1/2 / est)^(0.7/p) (est_before / (1/2))^(0.4/p),
  /// (b = 1.1, the factor within [0.2, 2], not above 1 after a rejection),
  /// kept at h when the factor lies in [1, b]: the matrices are not rebuilt
  /// for a small gain, and the set point is where the controller keeps the
  /// step. A step with est > 1 is tried again with h (1/2 / est)^(1/p) (at
  /// least h/5). At dt_min a step is accepted whatever its estimate
  /// (counted as forced), so that the run never stalls. Steps land on every
  /// output time (time_grid.h, plan_steps).
  /// A step that is not smooth (the active contact set changed in it: a
  /// node that closes puts a kink into u(t), which the estimate would
  /// measure instead of the scheme's error) is accepted as it is, counted
  /// (contact_breaks), and the predictor restarts after it; after a break,
  /// as at the start (t = 0, where loads switched on at t = 0+ make the
  /// state the one before a jump, the undrained response), the steps keep
  /// their length until order + 1 states lie beyond it (two for backward
  /// Euler, three for BDF2).
  bool judge(const StepSolution& step, TimeGrid& grid, AdaptiveReport& report, AdaptiveState& state,
             std::string& message);

  /// The accepted states y_{n-1}, y_{n-2}, y_{n-3} by checkpoint name.
  std::vector<std::pair<std::string, dolfinx::fem::Function<double>*>> history() const;

private:
  /// est of `step` (the header's formula). Milne's device: y_n minus the
  /// polynomial P through the last accepted states is a known multiple of
  /// the leading error term, so, with h1, h2 the steps before,
  ///   backward Euler: LTE = h / (2h + h1) (y_n - P),  P linear through
  ///                   y_{n-1}, y_{n-2} (error h (h + h1) y''/2, the step's h^2 y''/2);
  ///   BDF2:           LTE = E / (E + C) (y_n - P),    P quadratic through
  ///                   y_{n-1}, y_{n-2}, y_{n-3}, E = h^3 (1 + w) / (6 w c0),
  ///                   C = h (h + h1)(h + h1 + h2) / 6, w = h / h1.
  double estimate(const TimeGrid& grid, const StepSolution& step, AdaptiveState& state) const;
  void remember(std::span<const double> p, std::span<const double> u);

  const AdaptiveSpec _spec;
  const std::vector<double> _stops;
  const double _end;
  const int _order;      // p: 1 backward Euler, 2 BDF2
  bool _rejected = false; // the step being judged was rejected before
  // y_{n-1}, y_{n-2}, y_{n-3} of each field (empty for an absent one).
  std::vector<std::shared_ptr<dolfinx::fem::Function<double>>> _p, _u;
};

/// The coupling tolerance of a step of length h ending at t under
/// time.adaptive (error tolerance `error_tolerance`): coupling.tolerance,
/// at most a tenth of the error tolerance per unit step, tolerance h / t.
/// The iteration's own error enters the error estimate multiplied by t / h:
/// above that bound it would keep short steps short (a crawl at dt_min,
/// docs/theory.md "Adaptive steps").
double iteration_tolerance(double coupling_tolerance, double error_tolerance, double h, double t);

} // namespace biotcontact
