#include "closed_form.h"

#include <cmath>

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

} // namespace biotcontact
