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

from ..assembly.materials import HIGH_GAMMA, split_advice
from ..assembly.parameters import set_time_step, set_window_steps
from ..contact.bonds import BondFailure
from ..contact.contact_state import ActiveSet, same_active_set
from .contraction import ContractionMeasure, relative
from .coupling import CouplingError, IterationRecord
from .cycle import cycle_period, stagnates
from .pins import PinnedSteps, pin_cycle, pins_consistent, record_flags, release_pins
from .two_pass import second_pass_correction
from .window import (AndersonScales, Window, WindowFailure, WindowHistory, accelerate_window, fault_reference,
                     mix_iterates, not_converged_message, stagnation_note, window_name)
from ..time.window_control import window_limit, window_steps
from ..assembly.linear_algebra import owned, owned_norm
from ..scene.input import Acceleration
from ..solvers.solver import ITERATIVE_TOLERANCE, SolverError
from ..steps.flow_step import FlowStep
from ..steps.mechanics_step import MechanicsStep
from ..time.time_grid import FailedStep, retry_step
from ..time.step_control import StepSolution, iteration_tolerance


def inexact_tolerance(previous_increment):
    """Inexact coupling (cpp/coupling/fixed_stress.h): the relative tolerance of the
    iterative solves of an iteration, 1e-2 times the previous iteration's
    relative increment max(dp, du), between 1e-10 and 1e-4."""
    return min(max(1e-2 * previous_increment, ITERATIVE_TOLERANCE), 1e-4)


# The split's p_f, from the flow alone, can leave bonded pairs no state
# (BondFailure); the monolithic solve moves p_f with the openings.
_COHESIVE_SPLIT_ADVICE = ('; a cohesive fault opening along its length: coupling.scheme = "monolithic" solves p_f '
                          'with the contact')


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
        self.flow, self.second_pass, self.mechanics = steps.flow, steps.second_pass, steps.mechanics
        self.comm = problem.domain.mesh.comm
        self.measure = ContractionMeasure(problem, run, steps.mechanics.V, steps.flow.Q)
        self.history = WindowHistory(problem.scene.time_scheme, run.grid)  # p_K, u_K and the values before t_K
        self.observer, self.report, self.state = run.observer, run.report, run.state
        self.grid = run.grid
        self.control = run.control  # time.adaptive (q = 1), or None
        self.V, self.Q = steps.mechanics.V, steps.flow.Q
        self.advice = split_advice(problem.materials.gamma_peak(), self.coupling)  # for not_converged
        # coupling.acceleration = "auto" acts: not above HIGH_GAMMA, where G's
        # slowest modes (gamma) hide behind the rate seen, and the increments
        # bound the error no longer (docs/theory.md, "Anderson acceleration").
        self.rescued = (self.coupling.acceleration == Acceleration.automatic
                        and problem.materials.gamma_peak().gamma <= HIGH_GAMMA)
        self.attempts = [0]         # retries of the current window (time.retry)
        self.active_K = ActiveSet()  # contact active set at t_K

    def t(self, w, m):
        return self.history.t(w, m)

    def start(self):
        """The converged state at the start (t = 0 or the restart's window)
        and the scales of the stopping test: the largest p (root mean square
        over a window's fine steps) and u of the run so far (a restart brings
        its own)."""
        q_max = self.coupling.q_max if self.coupling.q_auto else self.coupling.q
        for step in (self.flow, self.second_pass):
            if step:
                step.keep_loads(q_max)
        self.history.start(self.flow, self.mechanics.u.x.array, self.report.fine_steps - self.state.window_q)
        self.active_K = self.mechanics.active_contact_set()
        if self.report.windows == 0:
            self.state.p_size = owned_norm(self.history.p_K, self.Q, self.comm)
            self.state.u_size = owned_norm(self.history.u_K, self.V, self.comm)

    def window_steps(self, j):
        """The fine steps of the window that starts at fine step j:
        coupling.q, or with q = "auto" those of window_steps
        (window_control.py) from the last window's relative change of u per
        unit time."""
        if not self.coupling.q_auto:
            return self.coupling.q
        rate = 0.0
        if self.report.windows > 0:
            h = self.history
            rate = (relative(owned_norm(h.u_K - h.u_before, self.V, self.comm), self.state.u_size)
                    / (self.grid.t[j] - self.grid.t[h.j_before]))
        return window_steps(self.grid, j, self.state.q_limit, rate, self.coupling.q_tolerance, self.scene.stops())

    def begin_window(self, K, j, q):
        """The first iterate of window K (fine steps j + 1, ..., j + q):
        p^{0,m} = p_K for all m, u^0 = u_K; with coupling.acceleration =
        "anderson" Anderson's method from the first iteration (accelerate)."""
        derivative = self.history.derivative(j, q)
        dt = derivative.effective_step(self.grid.dt[j])
        for flow in (self.flow, self.second_pass):
            if flow:
                flow.set_time_derivative(derivative)
                q_changed = set_window_steps(flow.F, q)
                if set_time_step(flow.F, dt):
                    flow.time_step_changed()  # all its operators, with the new q too
                elif q_changed:
                    flow.window_steps_changed()
        self.measure.set_window_steps(q)
        w = Window(K, j, q, self.flow.unknowns().copy(), self.history.p_K, self.history.u_K)
        w.derivative = derivative
        self.mechanics.begin_step()  # its u is u_K: the window's start, friction's reference
        self.flow.begin_step()  # its conduit faults' pressure is the window's start
        w.fault_new = [self.flow.fault_pressure.copy() for _ in range(q + 1)]
        self.flow.u_window.x.array[:] = self.history.u_K
        if self.second_pass:
            self.second_pass.u_window.x.array[:] = self.history.u_K
        if self.coupling.acceleration == Acceleration.anderson:
            self.accelerate(w)
        return w

    def accelerate(self, w):
        """Anderson's method from here on in window w (accelerate_window)."""
        accelerate_window(w, self.comm, self.coupling.depth,
                          AndersonScales(owned(self.Q), owned(self.V), self.state.p_size, self.state.u_size))
        w.active_set_changes = self.mechanics.active_set_changes()

    def stagnant(self, w, n):
        """coupling.acceleration = "auto": whether the plain iteration of
        window w stagnates after iteration n (cycle.py: a steady rate that
        would not reach the tolerance in the iterations left), in which case
        Anderson's method takes over the window, once, and the log says so."""
        left = self.coupling.max_iterations - n - 1
        if (not self.rescued or w.accelerated
                or not stagnates(w.increments, self.tolerance(w), left)):
            return False
        if self.observer.note:
            self.observer.note(stagnation_note(w, self.t(w, w.q), left))
        self.report.accelerated_windows += 1
        return True

    def tolerance(self, w):
        """The stopping test's tolerance of window w: coupling.tolerance, or
        time.adaptive's for its step."""
        if self.control is None:
            return self.coupling.tolerance
        return iteration_tolerance(self.coupling.tolerance, self.scene.adaptive.tolerance, self.grid.dt[w.j],
                                   self.t(w, w.q))

    def flow_pass(self, w):
        """(a) q flow steps with u^n lagged (eq. 4.17-4.19):
          ((S+L)(p^{n+1,m} - p^{n+1,m-1})/dt, th) + (div z^{n+1,m}, th)
            = (Q(t_m), th) + (L (p^{n,m} - p^{n,m-1})/dt, th)
              - ((alpha/q) div(u^n - u_K)/dt, th)
        (with BDF2, dt / c0 and the history values of WindowHistory)."""
        flow = self.flow
        if self.scene.solver.inexact_coupling:
            flow.system.set_tolerance(inexact_tolerance(w.increment))
            self.mechanics.system.set_tolerance(inexact_tolerance(w.increment))
        flow.u_iterate.x.array[:] = w.u_old
        w.fault_old = list(w.fault_new)  # its arrays are replaced, not changed
        for m in range(1, w.q + 1):
            self.history.set_time_history(flow, w, m, w.p_new, w.u_old)
            flow.p_iterate.x.array[:] = w.p_old[m]
            flow.p_iterate_previous.x.array[:] = self.history.previous(w, w.p_old, m)
            flow.set_fine_step(m, w.fault_new[m - 1], fault_reference(w, m))
            flow.solve(self.t(w, m))
            w.p_new[m] = flow.pressure.x.array.copy()
            w.w_new[m] = flow.unknowns().copy()
            w.fault_new[m] = flow.fault_pressure.copy()

    def conduits(self):
        """Whether the flow carries conduit faults' pressures (every rank
        alike)."""
        return self.flow.fault_aperture is not None

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
            second_pass_correction(self.second_pass, self.flow, w, self.history)

    def stopping_test(self, w, inc, n):
        """The stopping test's increments (ContractionMeasure's
        stopping_increments), logged; never on a stale state. With conduit
        faults dp is the larger of the rock's and the faults' p_f increment,
        both logged, with the faults' contraction ratio."""
        conduits = self.conduits()
        s = self.measure.stopping_increments(w, inc, n, conduits)
        if not math.isfinite(inc.p2) or not math.isfinite(s.du):
            # The iterates hold NaN or inf (a load or coefficient that is not
            # finite): no further iteration can recover.
            raise SolverError("non-finite values (NaN or inf) in the "
                              f"{'displacement' if math.isfinite(inc.p2) else 'pressure'}")
        w.active = self.mechanics.active_contact_set()
        self.observer.record(IterationRecord(w.K + 1, self.t(w, w.q), n + 1, inc.dsigma, inc.ratio,
                                             self.parameters.gamma, s.dp, s.du, w.active.nodes, s.fault_dp,
                                             s.fault_ratio, w.newton_steps))
        w.log.append(f" {n + 1}: dp {s.dp:g} du {s.du:g} dsigma {inc.dsigma:g}"
                     + (f" dp_f {s.fault_dp:g};" if conduits else ";"))
        return (max(s.dp, s.fault_dp) if conduits else s.dp), s.du

    def next_iterate(self, w):
        """The iterate the next flow pass reads: the map value (p^{n+1},
        u^{n+1}), or with Anderson a combination of the last map values. The
        differences of earlier iterations describe the map of their contact
        active set only: a new set restarts the history (too many, Anderson
        itself)."""
        changes = self.mechanics.active_set_changes()
        if w.anderson and changes != w.active_set_changes:
            w.active_set_changes = changes
            if not w.anderson.restart():  # the map kept changing: the plain iteration from here (anderson.py)
                w.anderson = None
        if w.anderson:
            return mix_iterates(w)
        w.p_old = list(w.p_new)
        w.u_old = w.u_new

    def iteration(self, w, n):
        """One coupling iteration n of window w; True when it converged."""
        self.flow_pass(w)
        self.mechanics_pass(w)
        inc = self.measure.measure(w, n)
        self.measure.hold_against_gamma(w, inc, n)
        dp_norm, du_norm = self.stopping_test(w, inc, n)
        self.next_iterate(w)
        if self.observer.iteration:
            self.observer.iteration(w.K + 1, n + 1, dp_norm, du_norm)
        w.increment = max(dp_norm, du_norm)
        w.active_nodes.append(w.active.nodes)
        record_flags(w)
        w.increments.append(w.increment)
        tolerance = self.tolerance(w)
        converged = dp_norm <= tolerance and du_norm <= tolerance
        if converged:
            self.measure.record_coupled_residual(w, inc, self.history, tolerance)
            # Compared once per window, on the converged iterate (one collective).
            w.contact_changed = not same_active_set(w.active, self.active_K, self.comm)
        return converged

    def iterate_window(self, w):
        """Iterates window w to convergence; returns the outcome and the last
        iteration's index."""
        n = 0
        try:
            pinned = PinnedSteps(self.mechanics, self.flow, self.comm, self.coupling.pin_cycles, self.observer.note,
                                 window_name(w, self.t(w, w.q)))
            release_pins(w, pinned)
            for n in range(self.coupling.max_iterations):
                if self.iteration(w, n) and pins_consistent(w, n, pinned):
                    return _Outcome.converged, n
                if self.stagnant(w, n):
                    self.accelerate(w)
                # A cycle goes on to max_iterations: end it here, unless pins end it.
                w.cycle = cycle_period(w.active_nodes, w.increments)
                if w.cycle and not pin_cycle(w, n, pinned):
                    return _Outcome.not_converged, n
        except SolverError as e:
            # The failing solve named its system; the iteration is known here.
            cause = f"coupling iteration {n + 1}: {e}"
            if isinstance(e, BondFailure):
                cause += _COHESIVE_SPLIT_ADVICE
            if not self.retry(w, cause):
                raise SolverError(cause) from None
            return _Outcome.retried, n
        return _Outcome.not_converged, n

    def go_back(self, w, message):
        """Back to the start of window w, to be computed again (`message`
        says why and on which steps)."""
        self.flow.set_unknowns(w.w_K)
        self.mechanics.u.x.array[:] = self.history.u_K
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
            message = f"{window_name(w, self.t(w, m))}: {failure}"
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
        coupling.max_iterations or cycled (cycle.py), with the last increments."""
        propose_retry = self.scene.retry == 0 and self.scene.has_contact()
        return CouplingError(not_converged_message(
            w, WindowFailure(self.t(w, w.q), self.coupling.max_iterations, self.advice, propose_retry)))

    def accept_window(self, w, n):
        """Accept the window: write every fine flow step, then the mechanics
        step; its end state is the next window's start."""
        report = self.report
        self.attempts[0] = 0
        report.pinned_windows += w.pin_rounds > 0
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
        self.history.accept(w, self.flow)

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
            if outcome == _Outcome.not_converged and not self.retry(
                    w, "the fixed-stress split cycles" if w.cycle else "the fixed-stress split did not converge"):
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
