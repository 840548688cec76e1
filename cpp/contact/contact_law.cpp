#include "contact/contact_law.h"

#include <algorithm>

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

PairStatus pair_status(const ContactLaw& law, const PairTraction& traction)
{
  if (!traction.closed)
    return PairStatus::open;
  const double bound = slip_bound(law, traction.normal);
  return traction.tangential < bound - status_tolerance * traction.scale ? PairStatus::stick : PairStatus::slip;
}

} // namespace biotcontact
