"""A coupling iteration that cycles: the contact set returning with a short
period while the increments stop shrinking, as the split does at a pair's
kink (docs/theory.md, "Flow in a fault"). Found, it ends the window at
once (a retry, or the error) instead of at coupling.max_iterations. Twin of
cpp/coupling/cycle.h."""

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
