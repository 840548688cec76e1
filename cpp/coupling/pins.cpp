#include "coupling/pins.h"

#include <algorithm>
#include <cstdint>
#include <string>

namespace biotcontact
{

namespace
{

/// The iteration goes on under new pins: the cycle's record and Anderson's
/// differences are of the map before them.
void restart_pinned(Window& w)
{
  ++w.pin_rounds;
  w.pinned_at += w.increments.size();
  w.active_nodes.clear();
  w.increments.clear();
  w.flags.clear();
  w.cycle = 0;
  if (w.anderson and !w.anderson->restart())
    w.anderson.reset();
}

/// Pins the pairs that change within the last w.cycle iterations, open;
/// how many, on all ranks.
int pin_changing_pairs(Window& w, MPI_Comm comm)
{
  const std::size_t period = static_cast<std::size_t>(w.cycle), last = w.flags.size() - 1;
  w.pins.resize(w.flags.back().size(), 0);
  int mine = 0, all = 0;
  for (std::size_t k = 0; k < w.pins.size(); ++k)
    for (std::size_t i = 1; i < period and w.pins[k] == 0; ++i)
      if (w.flags[last - i][k] != w.flags[last][k])
        w.pins[k] = -1, ++mine;
  MPI_Allreduce(&mine, &all, 1, MPI_INT, MPI_SUM, comm);
  return all;
}

/// The pairs pinned, on all ranks.
int pinned_pairs(const Window& w, MPI_Comm comm)
{
  int mine = static_cast<int>(std::count_if(w.pins.begin(), w.pins.end(), [](std::int8_t p) { return p != 0; }));
  int all = 0;
  MPI_Allreduce(&mine, &all, 1, MPI_INT, MPI_SUM, comm);
  return all;
}

void tell(const PinnedSteps& steps, int n, const std::string& what)
{
  if (steps.note)
    steps.note(steps.window + ", coupling iteration " + std::to_string(n + 1) + ": " + what);
}

} // namespace

void record_flags(Window& w)
{
  w.flags.push_back(w.active.flags);
  if (w.flags.size() > static_cast<std::size_t>(longest_cycle))
    w.flags.erase(w.flags.begin());
}

void release_pins(Window& w, const PinnedSteps& steps)
{
  w.pins.clear();
  w.pin_rounds = 0;
  steps.mechanics.pin_contact({});
  steps.flow.release_pins();
}

bool pin_cycle(Window& w, int n, const PinnedSteps& steps)
{
  if (!steps.enabled or w.pin_rounds < 0 or w.pin_rounds >= max_pin_rounds
      or w.flags.size() < static_cast<std::size_t>(w.cycle))
    return false;
  const int period = w.cycle, added = pin_changing_pairs(w, steps.comm);
  if (added == 0 and w.pin_rounds == 0)
    return false;
  if (added == 0) // pinned and cycling still (a pinned pair's penetration and its cells): the other state
  {
    for (std::int8_t& pin : w.pins)
      pin = static_cast<std::int8_t>(-pin);
    steps.flow.turn_pins();
  }
  steps.mechanics.pin_contact(w.pins);
  const int cells = steps.flow.pin_flipped();
  tell(steps, n,
       "the contact set cycles every " + std::to_string(period) + " iterations; "
           + (added ? "pinned open: " : "cycling though pinned, every pin turned: ")
           + std::to_string(pinned_pairs(w, steps.comm)) + " pairs, " + std::to_string(cells) + " fault cells");
  restart_pinned(w);
  return true;
}

bool pins_consistent(Window& w, int n, const PinnedSteps& steps)
{
  if (w.pin_rounds <= 0)
    return true;
  const std::vector<std::int8_t> pins = steps.mechanics.consistent_pins();
  int mine = pins != w.pins, turned = 0;
  MPI_Allreduce(&mine, &turned, 1, MPI_INT, MPI_MAX, steps.comm);
  const bool cells = steps.flow.turn_contradicted_pins();
  if (!turned and !cells)
    return true;
  if (w.pin_rounds >= max_pin_rounds)
  {
    tell(steps, n, "the iterate still contradicts its pins after " + std::to_string(max_pin_rounds)
                       + " rounds: released");
    release_pins(w, steps);
    w.pin_rounds = -1;
    return false;
  }
  tell(steps, n, "the converged iterate contradicts its pins: those turned");
  w.pins = pins;
  steps.mechanics.pin_contact(w.pins);
  restart_pinned(w);
  return false;
}

} // namespace biotcontact
