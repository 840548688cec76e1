"""The fixed-stress split, single-rate (q = 1) and multirate (q flow steps
per mechanics step): alg. "Single-rate fixed-stress split" and "Multirate
fixed-stress split" (paper section 4, eqs. 4.17-4.22), and the two-pass
multirate variant ("multirate-two-pass", docs/multirate-two-pass.md);
cpp/coupling/fixed_stress.{h,cpp}.
"""
import enum
import math
from dataclasses import dataclass
from typing import Optional

import numpy as np

from ..assembly.materials import split_advice
from ..assembly.parameters import set_time_step, set_window_steps
from .anderson import AndersonAcceleration
from ..contact.contact_state import ActiveSet, same_active_set
from .coupling import CouplingError, IterationRecord
from ..diagnostics.diagnostics import ContractionNorm
from ..time.window_control import window_limit, window_steps
from ..assembly.linear_algebra import owned, owned_norm
from ..scene.input import Acceleration, TimeScheme
from ..solvers.solver import ITERATIVE_TOLERANCE, SolverError
from ..steps.flow_step import FlowStep
from ..steps.mechanics_step import MechanicsStep
from ..time.time_grid import FailedStep, retry_step
from ..time.time_scheme import TimeDerivative, history_value, time_derivative
from ..time.step_control import StepSolution

# Ratios measured below this fraction of a window's first ||delta sigma||
# are at round-off level (see hold_against_gamma).
RESOLVED_FRACTION = 1e-6
ROUND_OFF_FRACTION = 1e-9


def inexact_tolerance(previous_increment):
    """Inexact coupling (cpp/coupling/fixed_stress.h): the relative tolerance of the
    iterative solves of an iteration, 1e-2 times the previous iteration's
    relative increment max(dp, du), between 1e-10 and 1e-4."""
    return min(max(1e-2 * previous_increment, ITERATIVE_TOLERANCE), 1e-4)


def _relative(increment, size):
    """increment / size, or the increment itself while size = 0."""
    return increment / size if size > 0 else increment


def _contact_changes(mechanics):
    """Changes of the contact active set so far (0 without contact)."""
    return mechanics.system.contact.active_set_changes if mechanics.system.has_contact() else 0


class _Window:
    """One window's iterates: p^{n,m} and p^{n+1,m} (m = 0..q; m = 0 is p_K),
    u^n and u^{n+1}, the mixed states (z, p)^{n+1,m}, and what the
    contraction measure and the error message carry from one iteration to
    the next."""

    def __init__(self, K, j, q, w_K, p_K, u_K):
        self.K = K                    # the window [t_K, t_{K+1}]
        self.j, self.q = j, q         # its first fine step and its fine steps: t_K = t_j, t_{K+1} = t_{j+q}
        self.active = ActiveSet()     # contact active set of u^{n+1} (the last iteration's)
        self.contact_changed = False  # converged active != the set at t_K
        self.derivative = TimeDerivative()  # of every fine step (time_scheme.py)
        self.w_K = w_K                # flow state (z, p) at t_K, for a retry
        self.p_old = [p_K] * (q + 1)
        self.p_new = [p_K] * (q + 1)
        self.w_new = [None] * (q + 1)
        self.u_old, self.u_new = u_K, None
        self.fault_old = self.fault_new = None  # the conduit faults' p_f^{n,m} and p_f^{n+1,m} (m = 0..q)
        self.anderson = None
        self.active_set_changes = 0   # at the last Anderson restart
        self.dsigma_previous, self.dsigma_first = math.nan, 0.0
        self.fault_previous = math.nan  # ||dp_f|| of the last iteration
        self.newton_steps = 0          # of the last mechanics pass's contact solve
        self.increment = 1.0          # max(dp, du) of the last iteration
        self.log = []                 # the last iterations, for the error message


class _Increments:
    """What one coupling iteration measured on its increments."""

    def __init__(self):
        self.du = None
        self.dsigma = 0.0    # ||delta sigma|| of Theorem 1 (q = 1) or 2 (multirate)
        self.theorem2 = 0.0  # Theorem 2's quantity (NaN without L)
        self.residual = 0.0  # L times it, cell by cell ("coupled_residual")
        self.ratio = 0.0     # dsigma / the previous iteration's (NaN at n = 0)
        self.dp2 = self.p2 = 0.0
        self.fault_dp = self.fault_p = 0.0  # ||dp_f|| and ||p_f|| (l2 over the conduit cells; 0 without)


class _Outcome(enum.Enum):
    converged = 1
    not_converged = 2
    retried = 3


class _FixedStressSplit:
    """The fixed-stress split as a sequence of windows, each iterated to
    convergence in the stages of paper section 4: flow pass (eq. 4.17-4.19),
    mechanics pass (eq. 4.20-4.22), contraction measure (Theorems 1 and 2),
    stopping test, next iterate, and accept or retry."""

    def __init__(self, problem, steps, run):
        self.scene, self.coupling, self.parameters = problem.scene, problem.scene.coupling, problem.parameters
        self.stabilised = problem.materials.max_L > 0  # L > 0 in some cell: Theorem 2's quantity is measured
        self.flow, self.second_pass, self.mechanics = steps.flow, steps.second_pass, steps.mechanics
        self.comm = problem.domain.mesh.comm
        self.contraction = ContractionNorm(problem.forms, problem.parameters.q, self.comm)
        self.observer, self.report, self.state = run.observer, run.report, run.state
        self.grid = run.grid
        self.control = run.control  # time.adaptive (q = 1), or None
        self.V, self.Q = steps.mechanics.V, steps.flow.Q
        self.accelerated = self.coupling.acceleration == Acceleration.anderson
        self.advice = split_advice(problem.materials.gamma_peak(), self.coupling.acceleration)  # for not_converged
        self.p_K = self.u_K = None  # the converged state at t_K
        # For BDF2: the pressure one fine step and the displacement one window
        # before t_K, and the displacement path's value one fine step before t_K.
        self.p_before = self.u_before = self.u_path_before = None
        self.j_before = 0           # the previous window's first fine step (t_{K-1})
        self.attempts = [0]         # retries of the current window (time.retry)
        self.active_K = ActiveSet()  # contact active set at t_K

    def t(self, w, m):
        """Fine time m of window w (t_K + m dt for a constant step)."""
        return self.grid.t[w.j + m]

    def start(self):
        """The converged state at the start (t = 0 or the restart's window)
        and the scales of the stopping test: the largest p (root mean square
        over a window's fine steps) and u of the run so far (a restart brings
        its own)."""
        q_max = self.coupling.q_max if self.coupling.q_auto else self.coupling.q
        for step in (self.flow, self.second_pass):
            if step:
                step.keep_loads(q_max)
        self.p_K = self.flow.pressure.x.array.copy()
        self.u_K = self.mechanics.u.x.array.copy()
        self.p_before = self.flow.p_before.x.array.copy()  # restored by a restart
        self.u_before = self.flow.u_before.x.array.copy()
        self.u_path_before = self.flow.u_path_before.x.array.copy()
        self.j_before = self.report.fine_steps - self.state.window_q
        self.active_K = self.mechanics.active_contact_set()
        if self.report.windows == 0:
            self.state.p_size = owned_norm(self.p_K, self.Q, self.comm)
            self.state.u_size = owned_norm(self.u_K, self.V, self.comm)

    def window_steps(self, j):
        """The fine steps of the window that starts at fine step j:
        coupling.q, or with q = "auto" those of window_steps
        (window_control.py) from the last window's relative change of u per
        unit time."""
        if not self.coupling.q_auto:
            return self.coupling.q
        rate = 0.0
        if self.report.windows > 0:
            rate = (_relative(owned_norm(self.u_K - self.u_before, self.V, self.comm), self.state.u_size)
                    / (self.grid.t[j] - self.grid.t[self.j_before]))
        return window_steps(self.grid, j, self.state.q_limit, rate, self.coupling.q_tolerance, self.scene.stops())

    def begin_window(self, K, j, q):
        """The first iterate of window K (fine steps j + 1, ..., j + q):
        p^{0,m} = p_K for all m, u^0 = u_K; with coupling.acceleration =
        "anderson" the Anderson state (p^1, ..., p^q, u), weighted by the
        scales of the stopping test (anderson.py)."""
        state = self.state
        derivative = self.window_derivative(j, q)
        dt = derivative.effective_step(self.grid.dt[j])
        for flow in (self.flow, self.second_pass):
            if flow:
                q_changed = set_window_steps(flow.F, q)
                if set_time_step(flow.F, dt):
                    flow.time_step_changed()  # all its operators, with the new q too
                elif q_changed:
                    flow.window_steps_changed()
        self.contraction.set_window_steps(q)
        w = _Window(K, j, q, self.flow.unknowns().copy(), self.p_K, self.u_K)
        w.derivative = derivative
        self.mechanics.begin_step()  # its u is u_K: the window's start, friction's reference
        self.flow.begin_step()  # its conduit faults' pressure is the window's start
        w.fault_new = [self.flow.fault_pressure.copy() for _ in range(q + 1)]
        self.flow.u_window.x.array[:] = self.u_K
        if self.second_pass:
            self.second_pass.u_window.x.array[:] = self.u_K
        w.active_set_changes = _contact_changes(self.mechanics)
        if self.accelerated:
            # p_size is a fine step's: the window's q pressures weigh as one field.
            p_size = math.sqrt(q) * state.p_size
            w.anderson = AndersonAcceleration(self.comm, self.coupling.depth,
                                              [owned(self.Q)] * q + [owned(self.V)],
                                              [1 / p_size if p_size > 0 else 1.0] * q
                                              + [1 / state.u_size if state.u_size > 0 else 1.0])
        return w

    def window_derivative(self, j, q):
        """The time derivative of window K's fine steps
        (cpp/coupling/fixed_stress.cpp): with q > 1 the fine steps share one
        matrix, so BDF2 needs the step before the window to equal the
        window's fine step; otherwise (the first window, a halved one)
        backward Euler, which keeps the global error second order."""
        dt, previous = self.grid.dt[j], self.grid.dt[j - 1] if j > 0 else 0.0
        if q > 1 and previous != dt:
            return TimeDerivative()
        return time_derivative(self.scene.time_scheme, dt, previous)

    def path(self, w, u, m):
        """The displacement of window w at its fine time m along the window's
        path from u_K to u (cpp/coupling/fixed_stress.cpp): backward Euler,
        the paper's straight line; BDF2, the quadratic through u_{K-1}, u_K, u
          Q(t_K + s) = u_K + s D1 + s (s - H) D2,  D1 = (u - u_K)/H,
          D2 = ((u - u_K)/H - (u_K - u_{K-1})/H1) / (H + H1),
        but in the first window u takes its end value at the first fine step
        and, with q > 1, the second window keeps the straight line."""
        bdf2 = self.scene.time_scheme == TimeScheme.bdf2
        if bdf2 and w.K == 0:
            return self.u_K if m == 0 else u
        H, s = self.t(w, w.q) - self.t(w, 0), self.t(w, m) - self.t(w, 0)
        D1 = (u - self.u_K) / H
        if not (bdf2 and (w.q == 1 or w.K > 1)):
            return self.u_K + s * D1
        H1 = self.t(w, 0) - self.grid.t[self.j_before]
        D2 = (D1 - (self.u_K - self.u_before) / H1) / (H + H1)
        return self.u_K + s * D1 + s * (s - H) * D2

    def set_time_history(self, flow, w, m, p, u):
        """The time history of fine step m of `flow` from p[0..m-1] and the
        window's displacement u: backward Euler reads p[m-1] and u_K (the
        paper's scheme); BDF2 differentiates the fluid content at the fine
        times with the window's derivative, p from its fine steps and u along
        the window's path:
          p* = (c1 p[m-1] - c2 p[m-2]) / c0,  u_window = u - q (Q(t_m) - Q*),
        the values one fine step before t_K being the previous window's."""
        if self.scene.time_scheme != TimeScheme.bdf2:
            flow.p_previous.x.array[:] = p[m - 1]
            return
        d = w.derivative
        flow.p_previous.x.array[:] = history_value(d, p[m - 1], p[m - 2] if m >= 2 else self.p_before)
        Q_star = history_value(d, self.path(w, u, m - 1),
                               self.path(w, u, m - 2) if m >= 2 else self.u_path_before)
        flow.u_window.x.array[:] = u - w.q * (self.path(w, u, m) - Q_star)

    def flow_pass(self, w):
        """(a) q flow steps with u^n lagged (eq. 4.17-4.19):
          ((S+L)(p^{n+1,m} - p^{n+1,m-1})/dt, th) + (div z^{n+1,m}, th)
            = (Q(t_m), th) + (L (p^{n,m} - p^{n,m-1})/dt, th)
              - ((alpha/q) div(u^n - u_K)/dt, th)
        (with BDF2, dt / c0 and the history values of set_time_history)."""
        flow, d = self.flow, w.derivative
        if self.scene.solver.inexact_coupling:
            flow.system.set_tolerance(inexact_tolerance(w.increment))
            self.mechanics.system.set_tolerance(inexact_tolerance(w.increment))
        flow.u_iterate.x.array[:] = w.u_old
        w.fault_old = list(w.fault_new)  # its arrays are replaced, not changed
        for m in range(1, w.q + 1):
            self.set_time_history(flow, w, m, w.p_new, w.u_old)
            flow.p_iterate.x.array[:] = w.p_old[m]
            flow.p_iterate_previous.x.array[:] = history_value(d, w.p_old[m - 1],
                                                               w.p_old[m - 2] if m >= 2 else self.p_before)
            flow.set_fine_step(m, w.fault_new[m - 1], self.fault_reference(w, m))
            flow.solve(self.t(w, m))
            w.p_new[m] = flow.pressure.x.array.copy()
            w.w_new[m] = flow.unknowns().copy()
            w.fault_new[m] = flow.fault_pressure.copy()

    def conduits(self):
        """Whether the flow carries conduit faults' pressures (every rank
        alike)."""
        return self.flow.fault_aperture is not None

    @staticmethod
    def fault_reference(w, m):
        """The reference of the conduit faults' fixed-stress term at fine
        step m, p_f^{n,m} - p_f^{n,m-1} + p_f^{n+1,m-1}: the fault's (S +
        L)(p_f^{n+1,m} - p_f^{n+1,m-1}) = L (p_f^{n,m} - p_f^{n,m-1}) + ...
        as the rock's eq. 4.17."""
        if m == 1:  # p_f^{n,0} = p_f^{n+1,0}: the window's start
            return w.fault_old[1]
        return w.fault_old[m] - w.fault_old[m - 1] + w.fault_new[m - 1]

    def mechanics_pass(self, w):
        """(b) mechanics (the VI) at t_{K+1} with p = p^{n+1,q} (eq.
        4.20-4.22): flow.pressure holds it and is the pressure coefficient of
        the mechanics load. (c) "multirate-two-pass": the fine steps again,
        without L, with u^{n+1}; for q = 1 the correction would return p^A_1
        itself."""
        before = self.mechanics.system.newton_steps()
        self.mechanics.solve(self.t(w, w.q))
        w.newton_steps = self.mechanics.system.newton_steps() - before
        w.u_new = self.mechanics.u.x.array.copy()
        if self.second_pass and w.q > 1:
            self.second_pass_correction(w)

    def second_pass_correction(self, w):
        """The second pass of "multirate-two-pass" (docs/multirate-two-pass.md):
        the fine steps again without L, from p_K and with u^{n+1},
          (S (p^B_m - p^B_{m-1})/dt, th) + (div z^B_m, th)
            = (Q(t_m), th) - ((alpha/q) div(u^{n+1} - u_K)/dt, th),
        then p^{n+1,m} = p^B_m + (m/q)(p^A_q - p^B_q) (and the same for the
        mixed states): the window end keeps p^A_q, the pressure the mechanics
        used. At the fixed point p^B = p^A: the fixed point is that of the
        printed scheme."""
        second, q = self.second_pass, w.q
        p_B, w_B, fault_B = [self.p_K] * (q + 1), [None] * (q + 1), [w.fault_new[0]] * (q + 1)
        second.u_iterate.x.array[:] = w.u_new
        if self.conduits():
            second.take_start_apertures(self.flow)
        for m in range(1, q + 1):
            self.set_time_history(second, w, m, p_B, w.u_new)
            second.set_fine_step(m, fault_B[m - 1], fault_B[m - 1])  # no L: the iterate is only the guess
            second.solve(self.t(w, m))
            p_B[m] = second.pressure.x.array.copy()
            w_B[m] = second.unknowns().copy()
            fault_B[m] = second.fault_pressure.copy()
        p_end, w_end = w.p_new[q] - p_B[q], w.w_new[q] - w_B[q]
        for m in range(1, q):
            w.p_new[m] = p_B[m] + (m / q) * p_end
            w.w_new[m] = w_B[m] + (m / q) * w_end
            # The conduit faults' pressures are the tail of the mixed states.
            w.fault_new[m] = w.w_new[m][len(w.w_new[m]) - len(w.fault_new[m]):].copy()

    def measure_contraction(self, w, n):
        """The contraction quantities of this iteration's increments, with the
        coefficients of each cell's material: Theorem 1,
          delta sigma_v^{n+1} = lambda div(du) - alpha dp,
        for the single-rate split, Theorem 2,
          delta sigma^{n+1,m} = (dp^m - dp^{m-1}) - alpha/(qL) div du,
        (summed over m in l2) for the multirate ones."""
        q, contraction = w.q, self.contraction
        inc = _Increments()
        inc.du = w.u_new - w.u_old
        dp_previous = np.zeros_like(self.p_K)
        for m in range(1, q + 1):
            dp = w.p_new[m] - w.p_old[m]
            if self.stabilised:
                change = dp - dp_previous
                inc.theorem2 += contraction("theorem2", inc.du if m == 1 else None, change) ** 2  # the same du
                inc.residual += contraction("coupled_residual", None, change) ** 2
            dp_previous = dp
            inc.dp2 += owned_norm(dp, self.Q, self.comm) ** 2
            inc.p2 += owned_norm(w.p_new[m], self.Q, self.comm) ** 2
        # ||dp_f||^2 and ||p_f||^2 summed over the fine steps; as p's, their
        # root mean square over the window.
        steps = range(1, q + 1)
        fault = self.comm.allreduce(np.array([sum(np.sum((w.fault_new[m] - w.fault_old[m]) ** 2) for m in steps),
                                              sum(np.sum(w.fault_new[m] ** 2) for m in steps)]))
        inc.fault_dp, inc.fault_p = np.sqrt(fault / q)
        inc.theorem2 = math.sqrt(inc.theorem2) if self.stabilised else math.nan
        inc.residual = math.sqrt(inc.residual)
        if self.coupling.multirate():
            inc.dsigma = inc.theorem2
        else:
            inc.dsigma = contraction("theorem1", inc.du, w.p_new[1] - w.p_old[1])
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
        parameters, q, report, ratio = self.parameters, w.q, self.report, inc.ratio
        if n == 0:
            w.dsigma_first = inc.dsigma
        if self.coupling.multirate():
            size = self.contraction("theorem2", w.u_new, w.p_new[q]) if self.stabilised else math.nan
        else:
            size = self.contraction("theorem1", w.u_new, w.p_new[1])
        resolved = (not self.accelerated and n > 1 and inc.dsigma >= RESOLVED_FRACTION * w.dsigma_first
                    and inc.dsigma >= ROUND_OFF_FRACTION * size)
        if n > 0 and not resolved:
            report.unresolved_ratios += 1
        if resolved and math.isfinite(ratio):
            report.max_contraction_ratio = max(report.max_contraction_ratio, ratio)
            self.state.ratio_sum += ratio
            report.ratios += 1
            report.bound_violations += int(ratio > parameters.gamma)
        w.dsigma_previous = inc.dsigma

    def stopping_test(self, w, inc, n):
        """The stopping test's increments (dp, du), logged: l2 norms of the p
        (root mean square over the window's fine steps) and u increments
        relative to the largest p and u of the run so far
        (relative to the current iterate alone, a field decaying to zero, e.g.
        p at steady state, would be judged by its round-off). Never on a
        stale state. With conduit faults dp is the larger of the rock's and
        the faults' p_f increment (relative to the largest p_f so far), both
        logged, with the faults' contraction ratio ||dp_f^{n+1}|| /
        ||dp_f^n||."""
        state = self.state
        state.p_size = max(state.p_size, math.sqrt(inc.p2 / w.q))
        state.u_size = max(state.u_size, owned_norm(w.u_new, self.V, self.comm))
        state.fault_p_size = max(state.fault_p_size, float(inc.fault_p))
        dp_norm = _relative(math.sqrt(inc.dp2 / w.q), state.p_size)
        du_norm = _relative(owned_norm(inc.du, self.V, self.comm), state.u_size)
        conduits = self.conduits()
        fault_dp = _relative(float(inc.fault_dp), state.fault_p_size) if conduits else math.nan
        resolved = conduits and n > 0 and w.fault_previous > 0
        fault_ratio = float(inc.fault_dp) / w.fault_previous if resolved else math.nan
        w.fault_previous = float(inc.fault_dp)
        if not math.isfinite(inc.p2) or not math.isfinite(state.u_size):
            # The iterates hold NaN or inf (a load or coefficient that is not
            # finite): no further iteration can recover.
            raise SolverError("non-finite values (NaN or inf) in the "
                              f"{'displacement' if math.isfinite(inc.p2) else 'pressure'}")
        w.active = self.mechanics.active_contact_set()
        self.observer.record(IterationRecord(w.K + 1, self.t(w, w.q), n + 1, inc.dsigma, inc.ratio,
                                             self.parameters.gamma, dp_norm, du_norm, w.active.nodes, fault_dp,
                                             fault_ratio, w.newton_steps))
        w.log.append(f" {n + 1}: dp {dp_norm:g} du {du_norm:g} dsigma {inc.dsigma:g}"
                     + (f" dp_f {fault_dp:g};" if conduits else ";"))
        return (max(dp_norm, fault_dp) if conduits else dp_norm), du_norm

    def next_iterate(self, w):
        """The iterate the next flow pass reads: the map value (p^{n+1},
        u^{n+1}), or with Anderson a combination of the last map values. The
        differences of earlier iterations describe the map of their contact
        active set only: a new set restarts the history."""
        if not w.anderson:
            w.p_old = list(w.p_new)
            w.u_old = w.u_new
            return
        changes = _contact_changes(self.mechanics)
        if changes != w.active_set_changes:
            w.anderson.restart()
            w.active_set_changes = changes
        x = w.anderson.next(w.p_old[1:] + [w.u_old], w.p_new[1:] + [w.u_new])
        w.p_old = [w.p_old[0]] + x[:w.q]
        w.u_old = x[w.q]

    def record_coupled_residual(self, w, inc):
        """Coupled residual of an accepted state: the flow equations with
        u^{n+1} in place of u^n differ by L(dp^m - dp^{m-1}) - (alpha/q) div du
        = L delta sigma^{n+1,m}; relative to the fluid content change."""
        if not self.stabilised:
            return
        change = self.contraction("fluid_content", w.u_new - self.u_K, w.p_new[w.q] - self.p_K)
        self.report.max_coupled_residual = max(self.report.max_coupled_residual,
                                               inc.residual / change if change > 0 else 0.0)

    def iteration(self, w, n):
        """One coupling iteration n of window w; True when it converged."""
        self.flow_pass(w)
        self.mechanics_pass(w)
        inc = self.measure_contraction(w, n)
        self.hold_against_gamma(w, inc, n)
        dp_norm, du_norm = self.stopping_test(w, inc, n)
        self.next_iterate(w)
        if self.observer.iteration:
            self.observer.iteration(w.K + 1, n + 1, dp_norm, du_norm)
        w.increment = max(dp_norm, du_norm)
        tolerance = self.stopping_tolerance(w)
        converged = dp_norm <= tolerance and du_norm <= tolerance
        if converged:
            self.record_coupled_residual(w, inc)
            # Compared once per window, on the converged iterate (one collective).
            w.contact_changed = not same_active_set(w.active, self.active_K, self.comm)
        return converged

    def stopping_tolerance(self, w):
        """The coupling tolerance of window w: coupling.tolerance, and under
        time.adaptive at most a tenth of the error tolerance per unit step,
        tolerance h / t. The iteration's own error enters the error estimate
        multiplied by t / h (step_control.py); above that bound it would keep
        short steps short (a crawl at dt_min, docs/theory.md "Adaptive steps")."""
        if self.control is None:
            return self.coupling.tolerance
        per_unit_step = self.scene.adaptive.tolerance * self.grid.dt[w.j] / self.t(w, w.q)
        return min(self.coupling.tolerance, 0.1 * per_unit_step)

    def iterate_window(self, w):
        """Iterates window w to convergence; returns the outcome and the last
        iteration's index."""
        n = 0
        try:
            for n in range(self.coupling.max_iterations):
                if self.iteration(w, n):
                    return _Outcome.converged, n
        except SolverError as e:
            # The failing solve named its system; the iteration is known here.
            cause = f"coupling iteration {n + 1}: {e}"
            if not self.retry(w, cause):
                raise SolverError(cause) from None
            return _Outcome.retried, n
        return _Outcome.not_converged, n

    def go_back(self, w, message):
        """Back to the start of window w, to be computed again (`message`
        says why and on which steps)."""
        self.flow.set_unknowns(w.w_K)
        self.mechanics.u.x.array[:] = self.u_K
        if self.observer.retry:
            self.observer.retry(message)

    def retry(self, w, cause):
        """time.retry: back to the start of the window, whose fine steps are
        halved (two windows of q steps); False when no retry is left."""
        message = retry_step(self.scene, FailedStep(w.K + 1, cause, w.j, w.q), self.attempts, self.report, self.grid)
        if message is None:
            return False
        self.go_back(w, message)
        return True

    def balance_accepted(self, w):
        """Whether every fine step of the converged window w conserves what
        it must (FlowStep.unbalanced: a conduit fault's volumes); if one
        does not, back to the window's start on halved steps (time.retry),
        or the run ends with the step and the fault named."""
        for m in range(1, w.q + 1 if self.conduits() else 1):
            self.flow.set_unknowns(w.w_new[m])
            self.flow.set_fine_step(m, w.fault_new[m - 1], w.fault_new[m])
            failure = self.flow.unbalanced(self.t(w, m))
            if not failure:
                continue
            message = f"step {w.K + 1} (t = {self.t(w, m):g}): {failure}"
            if self.retry(w, message):
                return False
            report = self.report
            report.mean_contraction_ratio = self.state.ratio_sum / report.ratios if report.ratios else 0.0
            raise CouplingError(message)
        return True

    def error_accepted(self, w):
        """time.adaptive: whether the converged window's error estimate accepts
        it (the control then plans the next steps; a window in which the
        active contact set changed is accepted unestimated); if not, back to
        its start, to be computed again on the shorter steps the control planned."""
        if self.control is None:
            return True
        accepted, message = self.control.judge(
            StepSolution(w.j + w.q, w.p_new[w.q], w.u_new, not w.contact_changed), self.grid, self.report.adaptive,
            self.state.adaptive)
        if accepted:
            return True
        self.go_back(w, message)
        return False

    def contact_accepted(self, w):
        """coupling.q = "auto": a window of q > 1 fine steps in which the
        contact active set changed is computed again with q = 1
        (the mechanics would have seen the change only at the window's end);
        the windows then grow again from q = 1 (window_limit)."""
        if not self.coupling.q_auto or w.q == 1 or not w.contact_changed:
            return True
        self.report.q_rejections += 1
        self.state.q_limit = 1
        self.go_back(w, f"step {w.K + 1}: the contact active set changed ({self.active_K.nodes} -> "
                        f"{w.active.nodes} nodes) in a window of q = {w.q}; again with q = 1")
        return False

    def not_converged(self, w):
        """The error of a window that did not converge in
        coupling.max_iterations, with the last increments."""
        return CouplingError(f"the fixed-stress split did not converge in {self.coupling.max_iterations} "
                             f"iterations at t = {self.t(w, w.q):g} (step {w.K + 1}); last increments:"
                             + "".join(w.log[-3:]) + " " + self.advice)

    def accept_window(self, w, n):
        """Accept the window: write every fine flow step, then the mechanics
        step; its end state is the next window's start."""
        report = self.report
        self.attempts[0] = 0
        for m in range(1, w.q + 1):
            self.flow.set_unknowns(w.w_new[m])
            self.flow.set_fine_step(m, w.fault_new[m - 1], w.fault_new[m])
            self.flow.accept(self.t(w, m))
            self.observer.flow_state(self.t(w, m))
        self.state.q_limit = window_limit(w.q, self.coupling.q_max, w.contact_changed)
        self.active_K = w.active
        report.windows, report.fine_steps, self.state.window_q = w.K + 1, w.j + w.q, w.q
        report.max_window_q = max(report.max_window_q, w.q)
        self.mechanics.accept(self.t(w, w.q))
        self.observer.mechanics_state(self.t(w, w.q), w.K + 1, n + 1)
        self.p_before = w.p_new[w.q - 1]  # p_K itself for q = 1
        self.u_path_before = self.path(w, w.u_new, w.q - 1)
        self.u_before = self.u_K
        self.j_before = w.j
        self.flow.p_before.x.array[:] = self.p_before
        self.flow.u_before.x.array[:] = self.u_before
        self.flow.u_path_before.x.array[:] = self.u_path_before
        self.p_K, self.u_K = w.p_new[w.q], w.u_new

    def run(self):
        report, max_iterations = self.report, self.coupling.max_iterations
        self.start()
        K, j = report.windows, report.fine_steps
        while j < self.grid.steps():
            w = self.begin_window(K, j, self.window_steps(j))
            outcome, n = self.iterate_window(w)
            if outcome != _Outcome.retried:
                iterations = min(n + 1, max_iterations)
                report.coupling_iterations += iterations
                report.max_iterations_per_step = max(report.max_iterations_per_step, iterations)
            if outcome == _Outcome.not_converged and not self.retry(w, "the fixed-stress split did not converge"):
                report.mean_contraction_ratio = self.state.ratio_sum / report.ratios if report.ratios else 0.0
                raise self.not_converged(w)
            if (outcome != _Outcome.converged or not self.balance_accepted(w) or not self.error_accepted(w)
                    or not self.contact_accepted(w)):
                continue  # the same window again, on the shorter steps or with q = 1
            self.accept_window(w, n)
            K, j = K + 1, w.j + w.q
            if self.observer.stop and self.observer.stop():
                break
        report.mean_contraction_ratio = self.state.ratio_sum / report.ratios if report.ratios else 0.0


@dataclass
class SplitSteps:
    """The steps the split drives: the flow step and the mechanics step, and
    for "multirate-two-pass" the flow step without L of its second pass
    (None for the other schemes)."""
    flow: FlowStep
    second_pass: Optional[FlowStep]
    mechanics: MechanicsStep


def run_fixed_stress(problem, steps, run):
    """Runs the coupled scene from t = 0 (or, when run.report.windows > 0,
    from the end of that window: a restart with the state loaded) to its end
    time on the steps of run.grid (which a retry refines), filling
    run.report as it goes and telling run.observer (a CouplingRun,
    coupling.py). Raises CouplingError (after logging every iteration) when
    a window does not converge; the report then describes the run up to that
    window."""
    _FixedStressSplit(problem, steps, run).run()
