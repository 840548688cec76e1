// Derived parameters of a coupled scene (alg. "Parameters" and the
// fixed-stress stabilisation L), and the UFL constants every form may use.
#pragma once

#include "scene/scene.h"

#include <dolfinx/fem/Constant.h>
#include <dolfinx/fem/Function.h>
#include <map>
#include <memory>
#include <string>

namespace biotcontact
{

using Constants = std::map<std::string, std::shared_ptr<const dolfinx::fem::Constant<double>>>;
using Coefficients = std::map<std::string, std::shared_ptr<const dolfinx::fem::Function<double>>>;

struct Parameters
{
  int d = 2;
  double G = 0, lambda = 0, alpha = 0;
  double storage = 0; // S = 1/M + c_f phi0
  double K_dr = 0;    // lambda + 2G/d
  double L = 0;       // stabilisation actually used
  /// Theorem 1 and 2 contraction factor gamma = alpha^2/(alpha^2 + lambda S)
  /// (of a material; the run's is the largest of its cells', materials.h).
  double gamma = 0;
  int q = 1;
  double dt = 0; // fine (flow) step
};

/// The parameters of the scene's top-level material.
Parameters derive_parameters(const Scene& scene);

/// The parameters of a region's material (its own L by coupling.L).
Parameters derive_parameters(const Scene& scene, const RegionSpec& region);

/// The constants of forms/biot.py, by UFL name, set from the parameters.
/// Unused ones stay at zero; create_form picks those a form names.
Constants make_constants(const Scene& scene, const Parameters& parameters);

/// mu_f K^-1 at the point x (row-major d x d): K from a scalar expression,
/// or a constant tensor; empty where the expression is not positive.
std::vector<double> resistivity(const FlowSpec& flow, int d, const double* x);

/// Sets the time step constant "dt" of `constants` (it changes during a
/// run with time.growth, time.adaptive and retries); returns whether it changed.
bool set_time_step(const Constants& constants, double dt);

/// Sets the constant "q" (the fine steps of the current window; it changes
/// between windows with coupling.q = "auto"); returns whether it changed.
bool set_window_steps(const Constants& constants, int q);

/// Interpolates one expression per component (at time t) into f.
void interpolate(dolfinx::fem::Function<double>& f, const std::vector<Expression>& components, double t);

} // namespace biotcontact
