"""The paper's contraction theorems measured on every coupling iteration of
the fixed-stress split (cpp/coupling/contraction.h): the increments of a
window's iterates, their ||delta sigma|| (Theorem 1 single-rate, Theorem 2
multirate) and its ratio held against gamma while resolved, the stopping
test's relative increments and the coupled residual of an accepted state
(docs/theory.md, "The theorems' quantities")."""
import math
from dataclasses import dataclass

import numpy as np
from mpi4py import MPI

from ..assembly.linear_algebra import owned_norm
from ..diagnostics.diagnostics import ContractionNorm

# Ratios measured below this fraction of a window's first ||delta sigma||
# are at round-off level (see hold_against_gamma).
RESOLVED_FRACTION = 1e-6
ROUND_OFF_FRACTION = 1e-9


def relative(increment, size):
    """increment / size, or the increment itself while size = 0."""
    return increment / size if size > 0 else increment


class Increments:
    """What one coupling iteration measured on its increments."""

    def __init__(self):
        self.du = None
        self.dsigma = 0.0    # ||delta sigma|| of Theorem 1 (q = 1) or 2 (multirate)
        self.theorem2 = 0.0  # Theorem 2's quantity (NaN without L)
        self.residual = 0.0  # L times it, cell by cell ("coupled_residual")
        self.ratio = 0.0     # dsigma / the previous iteration's (NaN at n = 0)
        self.dp2 = self.p2 = 0.0
        self.fault_dp = self.fault_p = 0.0  # ||dp_f|| and ||p_f|| (l2 over the conduit cells; 0 without)


@dataclass
class StoppingIncrements:
    """The stopping test's increments of one iteration: dp and du relative
    to the largest p and u of the run so far, and with conduit faults dp_f
    relative to the largest p_f and the faults' ratio ||dp_f^{n+1}|| /
    ||dp_f^n|| (NaN without)."""
    dp: float = 0.0
    du: float = 0.0
    fault_dp: float = 0.0
    fault_ratio: float = 0.0


class ContractionMeasure:
    """The contraction measures of the fixed-stress split's iterations,
    counted into the run's report (CouplingRun)."""

    def __init__(self, problem, run, V, Q):
        self.comm = problem.domain.mesh.comm
        self.norm = ContractionNorm(problem.forms, problem.parameters.q, self.comm)
        self.stabilised = problem.materials.max_L > 0  # L > 0 in some cell: Theorem 2's quantity is measured
        self.multirate = problem.scene.coupling.multirate()
        self.gamma = problem.parameters.gamma
        self.V, self.Q = V, Q
        self.report, self.state = run.report, run.state

    def set_window_steps(self, q):
        """Windows of q fine steps from now on (coupling.q = "auto")."""
        self.norm.set_window_steps(q)

    def measure(self, w, n):
        """The contraction quantities of this iteration's increments, with the
        coefficients of each cell's material: Theorem 1,
          delta sigma_v^{n+1} = lambda div(du) - alpha dp,
        for the single-rate split, Theorem 2,
          delta sigma^{n+1,m} = (dp^m - dp^{m-1}) - alpha/(qL) div du,
        (summed over m in l2) for the multirate ones."""
        q, norm = w.q, self.norm
        inc = Increments()
        inc.du = w.u_new - w.u_old
        dp_previous = np.zeros_like(w.p_new[0])
        for m in range(1, q + 1):
            dp = w.p_new[m] - w.p_old[m]
            if self.stabilised:
                change = dp - dp_previous
                inc.theorem2 += norm("theorem2", inc.du if m == 1 else None, change) ** 2  # the same du
                inc.residual += norm("coupled_residual", None, change) ** 2
            dp_previous = dp
            inc.dp2 += owned_norm(dp, self.Q, self.comm) ** 2
            inc.p2 += owned_norm(w.p_new[m], self.Q, self.comm) ** 2
        # ||dp_f||^2 and ||p_f||^2 summed over the fine steps; as p's, their
        # root mean square over the window.
        steps = range(1, q + 1)
        fault = np.array([sum(np.sum((w.fault_new[m] - w.fault_old[m]) ** 2) for m in steps),
                          sum(np.sum(w.fault_new[m] ** 2) for m in steps)], dtype=float)
        self.comm.Allreduce(MPI.IN_PLACE, fault)  # the buffer, not a pickled array
        inc.fault_dp, inc.fault_p = np.sqrt(fault / q)
        inc.theorem2 = math.sqrt(inc.theorem2) if self.stabilised else math.nan
        inc.residual = math.sqrt(inc.residual)
        if self.multirate:
            inc.dsigma = inc.theorem2
        else:
            inc.dsigma = norm("theorem1", inc.du, w.p_new[1] - w.p_old[1])
        with np.errstate(divide="ignore", invalid="ignore"):  # inf or nan after a zero, as in C++
            inc.ratio = np.float64(inc.dsigma) / w.dsigma_previous if n > 0 else math.nan
        return inc

    def hold_against_gamma(self, w, inc, n):
        """A ratio is held against gamma from the second one on, while the
        increments are resolved:
        - the first ratio compares with delta sigma^1 = sigma^1 - sigma^0, and
          u^0 = u_K is no mechanics solution at this step's loads, which the
          proof of Theorem 1 needs for both iterates it subtracts;
        - once ||delta sigma|| has fallen six orders below the window's first
          one, or below 1e-9 of the norm of the quantity itself, it is made of
          the round-off of the solves.
        The other ratios are logged and counted as unresolved. With
        acceleration the iterates are no longer x^{n+1} = G(x^n): ratios are
        logged only."""
        report, ratio = self.report, inc.ratio
        if n == 0:
            w.dsigma_first = inc.dsigma
        if self.multirate:
            size = self.norm("theorem2", w.u_new, w.p_new[w.q]) if self.stabilised else math.nan
        else:
            size = self.norm("theorem1", w.u_new, w.p_new[1])
        resolved = (not w.accelerated and n > 1 and inc.dsigma >= RESOLVED_FRACTION * w.dsigma_first
                    and inc.dsigma >= ROUND_OFF_FRACTION * size)
        if n > 0 and not resolved:
            report.unresolved_ratios += 1
        if resolved and math.isfinite(ratio):
            report.max_contraction_ratio = max(report.max_contraction_ratio, ratio)
            self.state.ratio_sum += ratio
            report.ratios += 1
            report.bound_violations += int(ratio > self.gamma)
        w.dsigma_previous = inc.dsigma

    def stopping_increments(self, w, inc, n, conduits):
        """The stopping test's increments: l2 norms of the p (root mean square
        over the window's fine steps) and u increments relative to the
        largest p and u of the run so far (relative to the current iterate
        alone, a field decaying to zero, e.g. p at steady state, would be
        judged by its round-off). With conduit faults also the p_f increment
        relative to the largest p_f so far, and the faults' contraction
        ratio."""
        state = self.state
        state.p_size = max(state.p_size, math.sqrt(inc.p2 / w.q))
        state.u_size = max(state.u_size, owned_norm(w.u_new, self.V, self.comm))
        state.fault_p_size = max(state.fault_p_size, float(inc.fault_p))
        s = StoppingIncrements(relative(math.sqrt(inc.dp2 / w.q), state.p_size),
                               relative(owned_norm(inc.du, self.V, self.comm), state.u_size))
        s.fault_dp = relative(float(inc.fault_dp), state.fault_p_size) if conduits else math.nan
        resolved = conduits and n > 0 and w.fault_previous > 0
        s.fault_ratio = float(inc.fault_dp) / w.fault_previous if resolved else math.nan
        w.fault_previous = float(inc.fault_dp)
        return s

    def record_coupled_residual(self, w, inc, history, tolerance):
        """Coupled residual of an accepted state: the flow equations with
        u^{n+1} in place of u^n differ by L(dp^m - dp^{m-1}) - (alpha/q) div du
        = L delta sigma^{n+1,m}; relative to the step's change of the fluid
        content's two terms, ||alpha div du|| + ||S dp||, not of their sum:
        an undrained step (an impermeable rock) changes them alike and its
        fluid content not at all, and the ratio was then 1 where the split
        had converged. A step that changes them by no more than `tolerance`
        of the state's own resolves no residual and is not recorded."""
        if not self.stabilised:
            return
        change = self._fluid_content_terms(w.u_new - history.u_K, w.p_new[w.q] - history.p_K)
        if change > tolerance * self._fluid_content_terms(w.u_new, w.p_new[w.q]):
            self.report.max_coupled_residual = max(self.report.max_coupled_residual, inc.residual / change)

    def _fluid_content_terms(self, u, p):
        """||alpha div u|| + ||S p||: the fluid content's two terms, each by
        its norm."""
        return self.norm("fluid_content", u, np.zeros_like(p)) + self.norm("fluid_content", np.zeros_like(u), p)
