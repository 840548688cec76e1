#include "time/step_control.h"

#include "assembly/linear_algebra.h"

#include <algorithm>
#include <cmath>
#include <sstream>

namespace biotcontact
{

namespace
{

// The PI controller's set point (the estimate it steers to) and the band of
// growth factors [1, band] that keep the step (step_control.h).
constexpr double target = 0.5, band = 1.1;

using Past = std::vector<std::shared_ptr<dolfinx::fem::Function<double>>>;

Past past_states(std::shared_ptr<const dolfinx::fem::FunctionSpace> space)
{
  Past past;
  for (int i = 0; space and i < 3; ++i)
    past.push_back(std::make_shared<dolfinx::fem::Function<double>>(space));
  return past;
}

/// The weight of the predictor's error against the step's own: the local
/// error is weight * (y_n - P) (step_control.h); t = (t_n, t_{n-1}, ...).
double milne_weight(int order, const double* t)
{
  const double h = t[0] - t[1], h1 = t[1] - t[2];
  if (order == 1)
    return h / (2 * h + h1);
  const double h2 = t[2] - t[3], w = h / h1, c0 = (1 + 2 * w) / (1 + w);
  const double E = h * h * h * (1 + w) / (6 * w * c0), C = h * (h + h1) * (h + h1 + h2) / 6;
  return E / (E + C);
}

/// ||LTE|| of one field: Milne's device with the Lagrange predictor of
/// degree `order` through the accepted states at t[1], ..., t[order + 1].
double local_error(std::span<const double> y, const Past& past, int order, const double* t,
                   const dolfinx::fem::FunctionSpace& V)
{
  std::vector<double> lagrange(order + 1, 1.0);
  for (int i = 1; i <= order + 1; ++i)
    for (int j = 1; j <= order + 1; ++j)
      if (j != i)
        lagrange[i - 1] *= (t[0] - t[j]) / (t[i] - t[j]);
  const double weight = milne_weight(order, t);
  std::vector<double> error(y.begin(), y.end());
  for (int i = 0; i <= order; ++i)
  {
    const auto yi = past[i]->x()->array();
    for (std::size_t j = 0; j < error.size(); ++j)
      error[j] -= lagrange[i] * yi[j];
  }
  for (double& e : error)
    e *= weight;
  return owned_norm(error, V);
}

} // namespace

StepControl::StepControl(const Scene& scene, std::shared_ptr<const dolfinx::fem::FunctionSpace> Q,
                         std::shared_ptr<const dolfinx::fem::FunctionSpace> V)
    : _spec(*scene.adaptive), _stops(scene.stops()), _end(scene.end_time),
      _order(scene.time_scheme == TimeScheme::bdf2 ? 2 : 1), _p(past_states(Q)), _u(past_states(V))
{
}

void StepControl::start(std::span<const double> p, std::span<const double> u, AdaptiveState& state)
{
  state.p_largest = _p.empty() ? 0.0 : owned_norm(p, *_p[0]->function_space());
  state.u_largest = _u.empty() ? 0.0 : owned_norm(u, *_u[0]->function_space());
}

void StepControl::remember(std::span<const double> p, std::span<const double> u)
{
  for (auto [past, y] : {std::pair{&_p, p}, std::pair{&_u, u}})
  {
    if (past->empty())
      continue;
    std::rotate(past->rbegin(), past->rbegin() + 1, past->rend()); // y_{n-3} is overwritten
    std::copy(y.begin(), y.end(), (*past)[0]->x()->mutable_array().begin());
  }
}

/// est of the step ending at t_k (step_control.h): the larger of the
/// pressure's and the displacement's relative local error per unit step.
double StepControl::estimate(const TimeGrid& grid, const StepSolution& step, AdaptiveState& state) const
{
  const int k = step.k;
  std::vector<double> times; // t_k, t_{k-1}, ..., t_{k-order-1}
  for (int i = 0; i <= _order + 1; ++i)
    times.push_back(grid.t[k - i]);
  double error = 0;
  for (auto [past, y, largest] :
       {std::tuple{&_p, step.p, &state.p_largest}, std::tuple{&_u, step.u, &state.u_largest}})
  {
    if (past->empty())
      continue;
    const auto& V = *(*past)[0]->function_space();
    *largest = std::max(*largest, owned_norm(y, V));
    if (*largest > 0)
      error = std::max(error, local_error(y, *past, _order, times.data(), V) / *largest);
  }
  return error * grid.t[k] / (grid.dt[k - 1] * _spec.tolerance);
}

bool StepControl::judge(const StepSolution& step, TimeGrid& grid, AdaptiveReport& report, AdaptiveState& state,
                        std::string& message)
{
  const int k = step.k;
  const bool smooth = step.smooth;
  const double h = grid.dt[k - 1], p_order = _order;
  // A predictor through order + 1 accepted states after the last break.
  const bool estimated = smooth and state.smooth_states > _order;
  const double est = estimated ? estimate(grid, step, state) : 0.0;
  if (est > 1 and h > _spec.dt_min * (1 + 1e-9))
  {
    const double shorter = std::max(_spec.dt_min, h * std::max(0.2, std::pow(target / est, 1 / p_order)));
    plan_steps(grid, k - 1, shorter, _stops);
    ++report.rejected_steps;
    _rejected = true;
    std::ostringstream s;
    s << "step " << k << " rejected: error estimate " << est << " > 1 (time.adaptive.tolerance); dt " << h
      << " -> " << shorter;
    message = s.str();
    return false;
  }
  report.forced_steps += est > 1;
  report.max_error_estimate = std::max(report.max_error_estimate, est);
  report.contact_breaks += !smooth;
  state.smooth_states = smooth ? state.smooth_states + 1 : 1;
  remember(step.p, step.u);
  double factor = 1;
  if (estimated)
  {
    const double before = state.error_estimate > 0 ? state.error_estimate : est;
    factor = est > 0 ? band * std::pow(target / est, 0.7 / p_order) * std::pow(before / target, 0.4 / p_order)
                     : 2.0;
    factor = std::clamp(factor, 0.2, _rejected ? 1.0 : 2.0);
    if (factor >= 1 and factor <= band)
      factor = 1;
    state.error_estimate = std::max(est, 1e-10);
  }
  _rejected = false;
  const double next = std::clamp(h * factor, _spec.dt_min, _spec.dt_max);
  if (next != h)
    plan_steps(grid, k, next, _stops);
  return true;
}

std::vector<std::pair<std::string, dolfinx::fem::Function<double>*>> StepControl::history() const
{
  std::vector<std::pair<std::string, dolfinx::fem::Function<double>*>> h;
  for (std::size_t i = 0; i < _p.size(); ++i)
    h.push_back({"adaptive_pressure_" + std::to_string(i + 1), _p[i].get()});
  for (std::size_t i = 0; i < _u.size(); ++i)
    h.push_back({"adaptive_displacement_" + std::to_string(i + 1), _u[i].get()});
  return h;
}

double iteration_tolerance(double coupling_tolerance, double error_tolerance, double h, double t)
{
  return std::min(coupling_tolerance, 0.1 * error_tolerance * h / t);
}

} // namespace biotcontact
