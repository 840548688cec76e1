// The discrete time derivative of the flow's accumulation term, the fluid
// content S p + alpha div u (alg. "Flow", docs/theory.md "Time schemes"):
// backward Euler (first order), or the variable-step BDF2 (second order),
//   d/dt y(t_{n+1}) ~ (c0 y_{n+1} - c1 y_n + c2 y_{n-1}) / dt_n,
//   w = dt_n / dt_{n-1}, c0 = (1 + 2w)/(1 + w), c1 = 1 + w, c2 = w^2/(1 + w),
// exact for quadratics in t. Since c0 - c1 + c2 = 0 it is backward Euler on
// the effective step dt_n / c0 from the history value
//   y* = (c1 y_n - c2 y_{n-1}) / c0,
// so the forms keep their backward-Euler shape: a step sets the "dt"
// constant to dt_n / c0 and reads y* where backward Euler reads y_n.
#pragma once

#include "scene/scene.h"

#include <array>
#include <span>
#include <string>
#include <vector>

namespace biotcontact
{

/// @brief The coefficients (c0, c1, c2) of one step's time derivative.
struct TimeDerivative
{
  double c0 = 1, c1 = 1, c2 = 0; // backward Euler by default

  /// The step the backward-Euler forms are assembled with: dt / c0.
  double effective_step(double dt) const { return dt / c0; }
  bool second_order() const { return c2 != 0; }
  /// (c0, c1, c2), as a conduit fault's FineStep takes them.
  std::array<double, 3> coefficients() const { return {c0, c1, c2}; }
};

/// The derivative of a step of length `dt` after one of `dt_previous`
/// under time.scheme `scheme`: BDF2 when the scheme is "bdf2" and there is a
/// previous step (dt_previous > 0), backward Euler otherwise (the first
/// step, which starts BDF2).
TimeDerivative time_derivative(TimeScheme scheme, double dt, double dt_previous);

/// The history value y* = (c1 y_n - c2 y_{n-1}) / c0 (y_n itself for
/// backward Euler).
std::vector<double> history_value(const TimeDerivative& d, std::span<const double> y,
                                  std::span<const double> y_before);

} // namespace biotcontact
