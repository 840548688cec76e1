#include "contact/contact_law.h"

#include <algorithm>
#include <cmath>

namespace biotcontact
{

ContactLaw contact_law(const FrictionSpec& friction)
{
  return {friction.friction, friction.cohesion, friction.tresca};
}

bool frictionless(const ContactLaw& law)
{
  return law.tresca ? *law.tresca == 0 : law.friction == 0 and law.cohesion == 0;
}

double slip_bound(const ContactLaw& law, double normal_traction)
{
  if (law.tresca)
    return *law.tresca;
  return law.cohesion + law.friction * std::max(normal_traction, 0.0);
}

double slip_bound_slope(const ContactLaw& law, double normal_traction)
{
  return !law.tresca and normal_traction > 0 ? law.friction : 0.0;
}

DiscProjection project_on_disc(double bound, const std::array<double, 2>& trial, int tangents)
{
  DiscProjection p;
  const double size = std::hypot(trial[0], tangents == 2 ? trial[1] : 0.0);
  // Strictly inside a disc of radius > 0: the bound 0 of an open or
  // frictionless constraint leaves it free, whatever theta.
  p.stick = bound > 0 and size <= bound;
  if (p.stick)
  {
    p.force = trial;
    p.d_trial = {1, 0, 0, 1};
    return p;
  }
  if (size == 0)
    return p;
  const std::array<double, 2> n{trial[0] / size, tangents == 2 ? trial[1] / size : 0.0};
  const double g = bound / size;
  for (int r = 0; r < tangents; ++r)
  {
    p.force[r] = bound * n[r];
    p.d_bound[r] = n[r];
    for (int q = 0; q < tangents; ++q)
      p.d_trial[2 * r + q] = g * ((r == q ? 1.0 : 0.0) - n[r] * n[q]);
  }
  return p;
}

PairStatus pair_status(const ContactLaw& law, const PairTraction& traction)
{
  if (!traction.closed)
    return PairStatus::open;
  const double bound = slip_bound(law, traction.normal);
  return traction.tangential < bound - status_tolerance * traction.scale ? PairStatus::stick : PairStatus::slip;
}

} // namespace biotcontact
