"""Pins that end a cycle of the fixed-stress split at a pair's kink
(cpp/coupling/pins.h; docs/theory.md, "Flow in a fault", "Pins"): the
pairs whose contact state changes within the cycle's period, and the
conduit cells whose open state flipped twice, are pinned open (the pairs'
bounds and the cells' kink removed: a smooth map), the iteration goes on,
and its converged iterate is accepted only where it is as pinned; the pins
it contradicts turn (a primal-dual active-set step)."""
from dataclasses import dataclass
from typing import Callable, Optional

import numpy as np
from mpi4py import MPI

from .cycle import LONGEST_CYCLE

# The rounds of pins a window may take: then they are released, and a
# cycle ends the window as without them.
MAX_PIN_ROUNDS = 4


@dataclass
class PinnedSteps:
    """The steps a window's pins act on, their communicator, whether
    cycles are pinned at all (coupling.pin_cycles), and who is told of each
    change of the pins (WindowObserver.note; may be None) with the window's
    name ("step K (t = ...)")."""
    mechanics: object  # MechanicsStep
    flow: object       # FlowStep
    comm: object
    enabled: bool = True
    note: Optional[Callable[[str], None]] = None
    window: str = ""


def _restart_pinned(w):
    """The iteration goes on under new pins: the cycle's record and
    Anderson's differences are of the map before them."""
    w.pin_rounds += 1
    w.pinned_at += len(w.increments)
    w.active_nodes, w.increments, w.flags, w.cycle = [], [], [], 0
    if w.anderson and not w.anderson.restart():
        w.anderson = None


def _pin_changing_pairs(w, comm):
    """Pins the pairs that change within the last w.cycle iterations, open;
    how many, on all ranks."""
    last = w.flags[-1]
    if len(w.pins) != len(last):
        w.pins = np.zeros(len(last), dtype=np.int8)
    changing = np.zeros(len(last), dtype=bool)
    for flags in w.flags[-w.cycle:-1]:
        changing |= flags != last
    new = changing & (w.pins == 0)
    w.pins[new] = -1
    return comm.allreduce(int(np.count_nonzero(new)), op=MPI.SUM)


def _tell(steps, n, what):
    if steps.note:
        steps.note(f"{steps.window}, coupling iteration {n + 1}: {what}")


def record_flags(w):
    """Keeps the active set of the window's last iteration, w.active's
    flags, with those of the iterations before it back to LONGEST_CYCLE
    (cycle.py): the most a cycle's period needs."""
    w.flags.append(w.active.flags)
    del w.flags[:-LONGEST_CYCLE]


def release_pins(w, steps):
    """A window starts without pins (collective)."""
    w.pins, w.pin_rounds = np.zeros(0, dtype=np.int8), 0
    steps.mechanics.pin_contact([])
    steps.flow.release_pins()


def pin_cycle(w, n, steps):
    """The window's iteration n cycles with period w.cycle: pins the pairs
    whose contact state changes within the period (the flags of the last
    w.cycle iterations) and the cells that flipped twice, open; while
    pinned, a cycle with no new pair turns every pin. Whether the iteration
    goes on pinned (collective)."""
    if not steps.enabled or w.pin_rounds < 0 or w.pin_rounds >= MAX_PIN_ROUNDS or len(w.flags) < w.cycle:
        return False
    period, added = w.cycle, _pin_changing_pairs(w, steps.comm)
    if added == 0 and w.pin_rounds == 0:
        return False
    if added == 0:  # pinned and cycling still (a pinned pair's penetration and its cells): the other state
        w.pins = -w.pins
        steps.flow.turn_pins()
    steps.mechanics.pin_contact(w.pins)
    cells = steps.flow.pin_flipped()
    pairs = steps.comm.allreduce(int(np.count_nonzero(w.pins)), op=MPI.SUM)
    _tell(steps, n, f"the contact set cycles every {period} iterations; "
          + ("pinned open: " if added else "cycling though pinned, every pin turned: ")
          + f"{pairs} pairs, {cells} fault cells")
    _restart_pinned(w)
    return True


def pins_consistent(w, n, steps):
    """The iteration n converged: whether its iterate is as pinned (True
    without pins). Else the contradicted pins turn and the iteration goes
    on; after MAX_PIN_ROUNDS the pins are released (collective)."""
    if w.pin_rounds <= 0:
        return True
    pins = steps.mechanics.consistent_pins()
    turned = steps.comm.allreduce(int(not np.array_equal(pins, w.pins)), op=MPI.MAX)
    cells = steps.flow.turn_contradicted_pins()
    if not turned and not cells:
        return True
    if w.pin_rounds >= MAX_PIN_ROUNDS:
        _tell(steps, n, f"the iterate still contradicts its pins after {MAX_PIN_ROUNDS} rounds: released")
        release_pins(w, steps)
        w.pin_rounds = -1
        return False
    _tell(steps, n, "the converged iterate contradicts its pins: those turned")
    w.pins = pins
    steps.mechanics.pin_contact(w.pins)
    _restart_pinned(w)
    return False
