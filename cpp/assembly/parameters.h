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
  /// Theorem 1 and 2 contraction factor gamma = alpha^2/(alpha^2 + lambda S).
  double gamma = 0;
  int q = 1;
  double dt = 0; // fine (flow) step
};

Parameters derive_parameters(const Scene& scene);

/// The constants of forms/biot.py, by UFL name, set from the parameters.
/// Unused ones stay at zero; create_form picks those a form names.
Constants make_constants(const Scene& scene, const Parameters& parameters);

/// mu_f K^-1 as a cell-wise d x d tensor: K from a scalar expression at
/// cell midpoints, or a constant tensor. Throws SceneError where K <= 0.
void interpolate_resistivity(dolfinx::fem::Function<double>& R, const FlowSpec& flow, int d);

/// Sets the time step constant "dt" of `constants` (the one constant that
/// changes during a run, with time.growth); returns whether it changed.
bool set_time_step(const Constants& constants, double dt);

/// Interpolates one expression per component (at time t) into f.
void interpolate(dolfinx::fem::Function<double>& f, const std::vector<Expression>& components, double t);

} // namespace biotcontact
