#include "diagnostics/closed_form.h"

#include <algorithm>
#include <cmath>
#include <memory>

namespace biotcontact
{
namespace
{
// Terms of the Fourier series are summed until the exponential factor
// drops below round-off (at t = 0 the series is cut at 20000 terms).
template <typename Term>
double series(double c, double h, double t, Term term)
{
  double sum = 0;
  for (int j = 1; j <= 20000; ++j)
  {
    const double k = 2 * j - 1;
    const double decay = std::exp(-k * k * M_PI * M_PI * c * t / (4 * h * h));
    if (decay < 1e-18)
      break;
    sum += term(j, k) * decay;
  }
  return sum;
}
} // namespace

double Terzaghi::pressure(double z, double t) const
{
  const double p0 = initial_pressure();
  return 4 * p0 / M_PI
         * series(consolidation_coefficient(), h, t,
                  [&](int j, double k)
                  { return (j % 2 == 1 ? 1.0 : -1.0) / k * std::cos(k * M_PI * z / (2 * h)); });
}

double Terzaghi::displacement(double z, double t) const
{
  // Uniaxial strain: (lambda + 2G) du/dz - alpha p = -load, u(0) = 0, so
  // u(z) = m_v (alpha int_0^z p ds - load z).
  const double p0 = initial_pressure();
  const double integral
      = 4 * p0 / M_PI
        * series(consolidation_coefficient(), h, t,
                 [&](int j, double k)
                 {
                   return (j % 2 == 1 ? 1.0 : -1.0) / k * (2 * h / (k * M_PI))
                          * std::sin(k * M_PI * z / (2 * h));
                 });
  return m_v() * (alpha * integral - load * z);
}

Mandel::Mandel(double a, double b, const Medium& medium, double F) : _a(a), _b(b), _G(medium.G), _F(F)
{
  const auto [G, lambda, alpha, storage, mobility] = medium;
  const double K = lambda + 2 * G / 3; // drained bulk modulus (3D)
  nu = (3 * K - 2 * G) / (2 * (3 * K + G));
  const double K_u = K + alpha * alpha / storage;
  B = alpha / (storage * K_u);
  nu_u = (3 * nu + B * (1 - 2 * nu)) / (3 - B * (1 - 2 * nu));
  consolidation_coefficient = 2 * mobility * B * B * G * (1 - nu) * (1 + nu_u) * (1 + nu_u)
                              / (9 * (1 - nu_u) * (nu_u - nu));
  // Roots of f(x) = tan x - c x, one in each ((n-1) pi, (n-1) pi + pi/2)
  // (c > 1), by bisection.
  const double c = (1 - nu) / (nu_u - nu);
  for (int n = 1; n <= 400; ++n)
  {
    double lo = (n - 1) * M_PI + 1e-12, hi = (n - 1) * M_PI + M_PI / 2 - 1e-12;
    for (int k = 0; k < 200; ++k)
    {
      const double mid = 0.5 * (lo + hi);
      (std::tan(mid) - c * mid < 0 ? lo : hi) = mid;
    }
    _roots.push_back(0.5 * (lo + hi));
  }
}

// Each series is cut where E_n(t) = exp(-a_n^2 c t / a^2) < 1e-18: the
// factor decays faster than geometrically in n and multiplies terms bounded
// by 1/(a_n - 1), so the rest is below round-off (and for t > 0 a few dozen
// terms replace 400, which made the closed-form errors of a fine mesh cost
// more than its solve).
constexpr double series_cut = 1e-18;

template <typename Term>
double Mandel::series(double t, Term term) const
{
  double sum = 0;
  for (double an : _roots)
  {
    const double E = std::exp(-an * an * consolidation_coefficient * t / (_a * _a));
    if (E < series_cut)
      break;
    sum += term(an, an - std::sin(an) * std::cos(an)) * E;
  }
  return sum;
}

double Mandel::pressure(double x, double t) const
{
  const double sum = series(t, [&](double an, double D)
                            { return std::sin(an) / D * (std::cos(an * x / _a) - std::cos(an)); });
  return 2 * _F * B * (1 + nu_u) / (3 * _a) * sum;
}

/// The plate's part of both displacements.
double Mandel::plate_series(double t) const
{
  return series(t, [](double an, double D) { return std::sin(an) * std::cos(an) / D; });
}

double Mandel::displacement_x(double x, double t) const
{
  const double s2 = series(t, [&](double an, double D) { return std::cos(an) / D * std::sin(an * x / _a); });
  return (_F * nu / (2 * _G * _a) - _F * nu_u / (_G * _a) * plate_series(t)) * x + _F / _G * s2;
}

double Mandel::displacement_y(double y, double t) const
{
  return (-_F * (1 - nu) / (2 * _G * _a) + _F * (1 - nu_u) / (_G * _a) * plate_series(t)) * y;
}

double sneddon_opening(double p, double E, double nu, double a, double s)
{
  return 4 * (1 - nu * nu) * p / E * std::sqrt(std::max(a * a - s * s, 0.0));
}

double penny_opening(double p, double E, double nu, double a, double r)
{
  return 8 * (1 - nu * nu) * p / (M_PI * E) * std::sqrt(std::max(a * a - r * r, 0.0));
}

double jansen_meulenbroek_slip(double y, DisplacedFault fault, double E, double nu, double alpha, double dp)
{
  // Jansen and Meulenbroek's slip is the trapezoid times C/A in size, with
  // C = (1 - 2 nu) alpha dp / (2 pi (1 - nu)) the scale of the shear stress
  // the depletion puts on a locked fault and A = G / (2 pi (1 - nu)) that of
  // an edge dislocation's: a slip gradient of size |C|/A, of opposite signs
  // on -b < y < -a and a < y < b, cancels the locked fault's logarithmic
  // shear stress everywhere on the line x = 0.
  const double G = E / (2 * (1 + nu));
  const auto [a, b] = fault;
  return -(1 - 2 * nu) * alpha * dp / G * std::clamp(b - std::abs(y), 0.0, b - a);
}

Scene with_mandel_plate(Scene scene)
{
  if (!scene.reference or scene.reference->solution != ReferenceSolution::mandel)
    return scene;
  const FlowSpec& f = *scene.flow;
  const Medium medium{scene.mechanics->G, scene.mechanics->lambda, scene.coupling->alpha, f.storage(),
                      (*f.permeability)(0, 0, 0, 0) / f.mu_f};
  auto mandel = std::make_shared<Mandel>(scene.mesh.upper[0], scene.mesh.upper[1], medium, scene.reference->force);
  BoundarySpec& plate = scene.boundaries.at(scene.reference->plate);
  plate.mechanics = BoundarySpec::Mechanics::displacement;
  plate.displacement[1] = Expression([mandel](double, double y, double, double t)
                                     { return mandel->displacement_y(y, t); },
                                     "Mandel's exact plate displacement");
  return scene;
}

} // namespace biotcontact
