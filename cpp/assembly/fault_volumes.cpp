#include "assembly/fault_volumes.h"

#include <algorithm>
#include <cmath>

namespace biotcontact
{

double volume_imbalance(const StepVolumes& step, const FaultVolumes& total, double rock_flux)
{
  const double scale = std::max({std::abs(total.injected), std::abs(total.stored), std::abs(total.exchanged),
                                 std::abs(total.outflow), std::abs(total.intersections), step.gross, 1e-6 * step.held,
                                 1e-8 * step.faces * rock_flux});
  const FaultVolumes& v = step.net;
  const double imbalance = std::abs(v.injected + v.exchanged + v.intersections - v.stored - v.outflow);
  return imbalance == 0 ? 0.0 : imbalance / scale; // NaN or inf when a volume is
}

} // namespace biotcontact
