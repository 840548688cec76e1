// Pins that end a cycle of the fixed-stress split at a pair's kink
// (docs/theory.md, "Flow in a fault", "Pins"): the pairs whose contact state
// changes within the cycle's period, and the conduit cells whose open state
// flipped twice, are pinned open (the pairs' bounds and the cells' kink
// removed: a smooth map), the iteration goes on, and its converged iterate is
// accepted only where it is as pinned; the pins it contradicts turn (a
// primal-dual active-set step). Twin: python_prototype/coupling/pins.py.
#pragma once

#include "coupling/cycle.h"
#include "coupling/window.h"
#include "steps/flow_step.h"
#include "steps/mechanics_step.h"

#include <functional>
#include <mpi.h>
#include <string>

namespace biotcontact
{

/// The rounds of pins a window may take: then they are released, and a
/// cycle ends the window as without them.
constexpr int max_pin_rounds = 4;

/// @brief The steps a window's pins act on, their communicator, whether
/// cycles are pinned at all (coupling.pin_cycles), and who is told of each
/// change of the pins (WindowObserver::note; may be empty) with the
/// window's name ("step K (t = ...)").
struct PinnedSteps
{
  MechanicsStep& mechanics;
  FlowStep& flow;
  MPI_Comm comm;
  bool enabled;
  std::function<void(const std::string&)> note;
  std::string window;
};

/// Keeps the active set of the window's last iteration, w.active's flags,
/// with those of the iterations before it back to longest_cycle
/// (coupling/cycle.h): the most a cycle's period needs.
void record_flags(Window& w);

/// A window starts without pins (collective).
void release_pins(Window& w, const PinnedSteps& steps);

/// The window's iteration n cycles with period w.cycle: pins the pairs
/// whose contact state changes within the period (the flags of the last
/// w.cycle iterations) and the cells that flipped twice, open; while
/// pinned, a cycle with no new pair turns every pin. Whether the iteration
/// goes on pinned (collective).
bool pin_cycle(Window& w, int n, const PinnedSteps& steps);

/// The iteration n converged: whether its iterate is as pinned (true
/// without pins). Else the contradicted pins turn and the iteration goes
/// on; after max_pin_rounds the pins are released (collective).
bool pins_consistent(Window& w, int n, const PinnedSteps& steps);

} // namespace biotcontact
