#include "time/time_scheme.h"

namespace biotcontact
{

TimeDerivative time_derivative(TimeScheme scheme, double dt, double dt_previous)
{
  if (scheme != TimeScheme::bdf2 or !(dt_previous > 0))
    return {};
  const double w = dt / dt_previous;
  return {(1 + 2 * w) / (1 + w), 1 + w, w * w / (1 + w)};
}

std::vector<double> history_value(const TimeDerivative& d, std::span<const double> y,
                                  std::span<const double> y_before)
{
  std::vector<double> out(y.begin(), y.end());
  if (!d.second_order())
    return out;
  for (std::size_t i = 0; i < out.size(); ++i)
    out[i] = (d.c1 * y[i] - d.c2 * y_before[i]) / d.c0;
  return out;
}

} // namespace biotcontact
