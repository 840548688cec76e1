// Pins on the conduit faults' open cells (ConduitFaults, fault_flow.h): a
// cell pinned open takes the fixed-stress term and a hydraulic aperture
// linear in its opening, one pinned closed the residual aperture, as the
// fixed-stress split asks where its contact set cycles (coupling/pins.h).
// Twin: python_prototype/assembly/fault_flow_pins.py.
#include "assembly/fault_flow.h"

#include <algorithm>

namespace biotcontact
{

int ConduitFaults::pin_flipped()
{
  int pinned = 0;
  for (Conduit& c : _conduits)
    for (std::size_t k = 0; k < c.pins.size(); ++k)
    {
      if (c.pins[k] == 0 and c.flips[k] >= 2)
        c.pins[k] = -1;
      pinned += c.pins[k] != 0;
    }
  // The relaxation that the flips started restarts on the map the pins leave.
  _relaxing = false;
  _relaxation = 1;
  _stalled = 0;
  _lags.clear();
  return pinned;
}

bool ConduitFaults::turn_contradicted_pins()
{
  bool turned = false;
  for (Conduit& c : _conduits)
  {
    const double e = open_fraction * c.residual;
    for (std::size_t k = 0; k < c.pins.size(); ++k)
      if ((c.pins[k] < 0 and c.opening[k] < -e) or (c.pins[k] > 0 and c.opening[k] > e))
        c.pins[k] = static_cast<signed char>(-c.pins[k]), turned = true;
  }
  return turned;
}

void ConduitFaults::turn_pins()
{
  for (Conduit& c : _conduits)
    for (signed char& pin : c.pins)
      pin = static_cast<signed char>(-pin);
}

void ConduitFaults::release_pins()
{
  for (Conduit& c : _conduits)
    std::fill(c.pins.begin(), c.pins.end(), 0);
}

} // namespace biotcontact
