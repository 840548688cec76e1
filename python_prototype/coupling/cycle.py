"""A coupling iteration that will not converge: one that cycles (the contact
set returning with a short period while the increments stop shrinking, as
the split does at a pair's kink), found, ends the window at once (a retry,
or the error); one that stagnates (a steady rate near 1, as the split's
over-stabilised mode of a fault's open patch) is handed to Anderson's
method by coupling.acceleration = "auto" (docs/theory.md, "Flow in a
fault"). Twin of cpp/coupling/cycle.h."""
import math

LONGEST_CYCLE = 4    # the longest period a cycle is looked for with
CYCLE_SHRINK = 0.9995  # an increment below this fraction of the one a period before is shrinking


def cycle_period(active_nodes, increments):
    """The period P (2 .. LONGEST_CYCLE) of the cycle the last iterations
    show, 0 when they show none; the smallest such P. A cycle of period P:
    the active contact nodes of the last 3P iterations repeat with period P
    and change within it, and no increment of the last 2P iterations is
    below CYCLE_SHRINK times the one P iterations before. One entry per
    iteration, the last iteration's last (the same on every rank)."""
    n = min(len(active_nodes), len(increments))
    for P in range(2, LONGEST_CYCLE + 1):
        if n < 3 * P:
            return 0
        last = range(n - 2 * P, n)
        periodic = all(active_nodes[i] == active_nodes[i - P] for i in last)
        shrinking = any(increments[i] < CYCLE_SHRINK * increments[i - P] for i in last)
        changes = any(active_nodes[i] != active_nodes[n - 1] for i in range(n - P, n))
        if periodic and changes and not shrinking:
            return P
    return 0


STEADY_ITERATIONS = 5  # the iterations a steady rate is judged on
FIRST_JUDGED = 10      # the first iteration judged: the start of a step's iteration may wander
STAGNANT_RATE = 0.9    # a steady rate: each of the last ratios in [STAGNANT_RATE, SLOWEST_RATE] ...
STEADY_SPREAD = 0.02   # ... and within STEADY_SPREAD of the last
# Above SLOWEST_RATE the increments no longer bound the error (about r/(1 - r)
# times the last, 1000 times at 0.999): gamma near 1, the monolithic scheme's
# case, where the split ends in its error as before.
SLOWEST_RATE = 0.999


def stagnates(increments, tolerance, left):
    """Whether the iteration stagnates: from iteration FIRST_JUDGED on, its
    increments shrink at a steady rate r (each of the last STEADY_ITERATIONS
    ratios of consecutive increments in [STAGNANT_RATE, SLOWEST_RATE] and within
    STEADY_SPREAD of the last) so slowly that at r the last increment would
    not reach `tolerance` within `left` iterations. One entry per iteration,
    the last iteration's last (the same on every rank)."""
    n = len(increments)
    if n < max(FIRST_JUDGED, STEADY_ITERATIONS + 1) or not increments[-1] > tolerance:
        return False
    last = increments[-1] / increments[-2]
    ratios = [increments[i] / increments[i - 1] for i in range(n - STEADY_ITERATIONS, n)]
    if not all(STAGNANT_RATE <= r <= SLOWEST_RATE and abs(r - last) <= STEADY_SPREAD for r in ratios):
        return False
    # The iterations the slowest of the steady ratios needs: log(tol / e) / log(r).
    return math.log(tolerance / increments[-1]) / math.log(max(ratios)) > left
