"""The fixed-stress split, single-rate (q = 1) and multirate (q flow steps
per mechanics step): algorithm.md "Single-rate fixed-stress split" and
"Multirate fixed-stress split" (paper eqs. 4.17-4.22), and the two-pass
multirate variant ("multirate-two-pass", docs/multirate-two-pass.md); cpp/coupling/fixed_stress.cpp.
"""
import math

import numpy as np

from ..assembly.parameters import set_time_step
from .anderson import AndersonAcceleration
from ..assembly.linear_algebra import owned, owned_norm
from ..solvers.solver import ITERATIVE_TOLERANCE, SolverError
from ..steps.time_grid import retry_step

# Ratios measured below this fraction of a window's first ||delta sigma||
# are at round-off level (see the loop).
RESOLVED_FRACTION = 1e-6
ROUND_OFF_FRACTION = 1e-9


class CouplingError(Exception):
    """The split did not converge within coupling.max_iterations."""


class CouplingReport:
    def __init__(self):
        self.windows = 0                   # mechanics (coarse) steps
        self.coupling_iterations = 0
        self.max_iterations_per_step = 0
        self.max_contraction_ratio = self.mean_contraction_ratio = 0.0
        self.ratios = 0                    # ratios held against gamma (resolved)
        self.bound_violations = 0          # resolved ratios above gamma
        self.unresolved_ratios = 0         # ratios at round-off level, logged only
        self.max_coupled_residual = 0.0    # relative, of each converged state
        self.retries = 0                   # failed steps retried with halved steps (time.retry)
        # Carried from window to window (and through a checkpoint): the sum
        # of the resolved ratios and the scales of the stopping test.
        self.ratio_sum = self.p_size = self.u_size = 0.0


def inexact_tolerance(previous_increment):
    """Inexact coupling (cpp/coupling/fixed_stress.h): the relative tolerance of the
    iterative solves of an iteration, 1e-2 times the previous iteration's
    relative increment max(dp, du), between 1e-10 and 1e-4."""
    return min(max(1e-2 * previous_increment, ITERATIVE_TOLERANCE), 1e-4)


def relative(increment, size):
    """increment / size, or the increment itself while size = 0."""
    return increment / size if size > 0 else increment


def contact_changes(mechanics):
    """Changes of the contact active set so far (0 without contact)."""
    return mechanics.system.contact.active_set_changes if mechanics.system.has_contact() else 0


def second_pass_correction(second, p_K, u_new, t, p_new, w_new):
    """The second pass of "multirate-two-pass" (cpp/coupling/fixed_stress.cpp): the
    fine steps again without L, from p_K and with u^{n+1},
      (S (p^B_m - p^B_{m-1})/dt, th) + (div z^B_m, th)
        = (Q(t_m), th) - ((alpha/q) div(u^{n+1} - u_K)/dt, th),
    then p^{n+1,m} = p^B_m + (m/q)(p^A_q - p^B_q) (and the same for the mixed
    states): the window end keeps p^A_q, the pressure the mechanics used."""
    q = len(p_new) - 1
    p_B, w_B = [p_K] * (q + 1), [None] * (q + 1)
    second.u_iterate.x.array[:] = u_new
    for m in range(1, q + 1):
        second.p_previous.x.array[:] = p_B[m - 1]
        second.solve(t(m))
        p_B[m] = second.pressure.x.array.copy()
        w_B[m] = second.state().copy()
    p_end, w_end = p_new[q] - p_B[q], w_new[q] - w_B[q]
    for m in range(1, q):
        p_new[m] = p_B[m] + (m / q) * p_end
        w_new[m] = w_B[m] + (m / q) * w_end


def run_fixed_stress(scene, P, F, flow, second_pass, mechanics, contraction, output, on_flow_state,
                     on_mechanics_state, report, comm, grid, stop=None, on_retry=None):
    """Runs the coupled scene to its end time (from the end of window
    report.windows when a restart loaded its state) on the steps of `grid`
    (which a retry refines), filling `report`. After each converged window
    calls on_flow_state(t) once per fine step (with that step's solution
    loaded in `flow`), then on_mechanics_state(t, window, iterations), then
    stop(): true ends the run there (an interruption); on_retry(message)
    when a failed window is tried again with halved steps. Raises
    CouplingError when a window does not converge. `second_pass` is the flow
    step without L of "multirate-two-pass" (None for the other schemes)."""
    coupling, q = scene.coupling, P.q
    multirate = coupling.multirate()
    accelerated = coupling.acceleration == "anderson"
    V, Q = mechanics.V, flow.Q
    nan = math.nan
    for step in (flow, second_pass):
        if step:
            step.keep_loads(q)

    # Converged state at t_K: (u_K, p_K).
    p_K = flow.pressure.x.array.copy()
    u_K = mechanics.u.x.array.copy()
    # The largest p (summed over the q fine steps) and u of the run so far:
    # the scales of the stopping test (a restart brings its own).
    if report.windows == 0:
        report.p_size = math.sqrt(q) * owned_norm(p_K, Q, comm)
        report.u_size = owned_norm(u_K, V, comm)

    attempts = [0]  # retries of the current window (time.retry)
    K = report.windows
    while K < grid.steps() // q:
        def t(m):  # fine time m of the window (t_K + m dt for a constant step)
            return grid.t[K * q + m]
        if set_time_step(F, grid.dt[K * q]):
            flow.time_step_changed()
        if second_pass and set_time_step(second_pass.F, grid.dt[K * q]):
            second_pass.time_step_changed()
        w_K = flow.state().copy()

        def retry(cause):
            """time.retry: back to the start of the window, whose fine steps
            are halved (two windows of q steps); False when no retry is left."""
            message = retry_step(scene, cause, K + 1, attempts, grid, K * q, q, report)
            if message is None:
                return False
            flow.set_state(w_K)
            mechanics.u.x.array[:] = u_K
            if on_retry:
                on_retry(message)
            return True
        # Start: p^{0,m} = p_K for all m, u^0 = u_K.
        p_old = [p_K] * (q + 1)
        p_new = [p_K] * (q + 1)
        w_new = [None] * (q + 1)
        u_old = u_K
        flow.u_window.x.array[:] = u_K
        if second_pass:
            second_pass.u_window.x.array[:] = u_K
        # coupling.acceleration = "anderson": the iterate fed to the next pass
        # combines the last map values (anderson.py); state (p^1..p^q, u),
        # weighted by the scales of the stopping test.
        anderson, active_set_changes = None, contact_changes(mechanics)
        if accelerated:
            owned_p, owned_u = owned(Q), owned(V)
            anderson = AndersonAcceleration(comm, coupling.depth, [owned_p] * q + [owned_u],
                                            [1 / report.p_size if report.p_size > 0 else 1.0] * q
                                            + [1 / report.u_size if report.u_size > 0 else 1.0])
        dsigma_previous, dsigma_first = nan, 0.0
        converged, log = False, []
        increment = 1.0  # max(dp, du) of the last iteration

        n = 0
        try:
            for n in range(coupling.max_iterations):
                # (a) q flow steps with u^n lagged:
                #   ((S+L)(p^{n+1,m} - p^{n+1,m-1})/dt, th) + (div z^{n+1,m}, th)
                #     = (Q(t_m), th) + (L (p^{n,m} - p^{n,m-1})/dt, th)
                #       - ((alpha/q) div(u^n - u_K)/dt, th)
                if scene.solver.inexact_coupling:
                    flow.system.set_tolerance(inexact_tolerance(increment))
                    mechanics.system.set_tolerance(inexact_tolerance(increment))
                flow.u_iterate.x.array[:] = u_old
                for m in range(1, q + 1):
                    flow.p_previous.x.array[:] = p_new[m - 1]
                    flow.p_iterate.x.array[:] = p_old[m]
                    flow.p_iterate_previous.x.array[:] = p_old[m - 1]
                    flow.solve(t(m))
                    p_new[m] = flow.pressure.x.array.copy()
                    w_new[m] = flow.state().copy()
                # (b) mechanics (the VI) at t_{K+1} with p = p^{n+1,q}: flow.pressure
                # holds it and is the pressure coefficient of the mechanics load.
                mechanics.solve(t(q))
                u_new = mechanics.u.x.array.copy()
                # (c) "multirate-two-pass": the fine steps again, without L, with
                # u^{n+1}; for q = 1 the correction returns p^A_1 itself.
                if second_pass and q > 1:
                    second_pass_correction(second_pass, p_K, u_new, t, p_new, w_new)

                # Contraction quantities, measured on the increments of this iteration.
                du = u_new - u_old
                theorem2, dp2, p2 = 0.0, 0.0, 0.0
                dp_previous = np.zeros_like(p_K)
                for m in range(1, q + 1):
                    dp = p_new[m] - p_old[m]
                    # Theorem 2: delta sigma^{n+1,m} = (dp^m - dp^{m-1}) - alpha/(qL) div du
                    if P.L > 0:
                        theorem2 += contraction(P.alpha / (q * P.L), du, 1.0, dp - dp_previous) ** 2
                    dp_previous = dp
                    dp2 += owned_norm(dp, Q, comm) ** 2
                    p2 += owned_norm(p_new[m], Q, comm) ** 2
                theorem2 = math.sqrt(theorem2) if P.L > 0 else nan
                if multirate:
                    dsigma = theorem2
                else:  # Theorem 1: delta sigma_v^{n+1} = lambda div(du) - alpha dp
                    dsigma = contraction(P.lmbda, du, P.alpha, p_new[1] - p_old[1])

                ratio = dsigma / dsigma_previous if n > 0 else nan
                if n == 0:
                    dsigma_first = dsigma
                # A ratio is held against gamma from the second one on, while the
                # increments are resolved:
                # - the first ratio compares with delta sigma^1 = sigma^1 - sigma^0,
                #   and u^0 = u_K is no mechanics solution at this step's loads, which
                #   the proof of Theorem 1 needs for both iterates it subtracts;
                # - once ||delta sigma|| has fallen six orders below the window's
                #   first one, or below 1e-9 of the norm of the quantity itself, it
                #   is made of the round-off of the solves.
                # The other ratios are logged and counted as unresolved.
                if multirate:
                    size = contraction(P.alpha / (q * P.L), u_new, 1.0, p_new[q]) if P.L > 0 else nan
                else:
                    size = contraction(P.lmbda, u_new, P.alpha, p_new[1])
                # with acceleration the iterates are no longer x^{n+1} = G(x^n):
                # the ratios are logged, not held against gamma
                resolved = (not accelerated and n > 1 and dsigma >= RESOLVED_FRACTION * dsigma_first
                            and dsigma >= ROUND_OFF_FRACTION * size)
                if n > 0 and not resolved:
                    report.unresolved_ratios += 1
                if resolved and math.isfinite(ratio):
                    report.max_contraction_ratio = max(report.max_contraction_ratio, ratio)
                    report.ratio_sum += ratio
                    report.ratios += 1
                    report.bound_violations += int(ratio > P.gamma)
                dsigma_previous = dsigma

                # Stopping test on the increments of this iteration (never on a
                # stale state): l2 norms of the p and u increments relative to the
                # largest p and u of the run so far (relative to the current iterate
                # alone, a field decaying to zero would be judged by its round-off).
                report.p_size = max(report.p_size, math.sqrt(p2))
                report.u_size = max(report.u_size, owned_norm(u_new, V, comm))
                dp_norm = relative(math.sqrt(dp2), report.p_size)
                du_norm = relative(owned_norm(du, V, comm), report.u_size)
                if not math.isfinite(p2) or not math.isfinite(report.u_size):
                    # The iterates hold NaN or inf (a load or coefficient that is
                    # not finite): no further iteration can recover.
                    raise SolverError("non-finite values (NaN or inf) in the "
                                      f"{'displacement' if math.isfinite(p2) else 'pressure'}")
                output.iteration(K + 1, t(q), n + 1, dsigma, ratio, P.gamma, dp_norm, du_norm,
                                 mechanics.active_contact_nodes())
                log.append(f" {n + 1}: dp {dp_norm:g} du {du_norm:g} dsigma {dsigma:g};")

                if anderson:
                    # earlier differences describe the map of their active set only
                    changes = contact_changes(mechanics)
                    if changes != active_set_changes:
                        anderson.restart()
                        active_set_changes = changes
                    x = anderson.next(p_old[1:] + [u_old], p_new[1:] + [u_new])
                    p_old = [p_old[0]] + x[:q]
                    u_old = x[q]
                else:
                    p_old = list(p_new)
                    u_old = u_new
                increment = max(dp_norm, du_norm)
                if dp_norm <= coupling.tolerance and du_norm <= coupling.tolerance:
                    converged = True
                    # Coupled residual of the accepted state: the flow equations with
                    # u^{n+1} in place of u^n differ by L(dp^m - dp^{m-1}) - (alpha/q)
                    # div du = L delta sigma^{n+1,m}; relative to the fluid content change.
                    if P.L > 0:
                        change = contraction(P.alpha, u_new - u_K, -P.storage, p_new[q] - p_K)
                        report.max_coupled_residual = max(report.max_coupled_residual,
                                                          P.L * theorem2 / change if change > 0 else 0.0)
                    break
        except SolverError as e:
            # The failing solve named its system; the iteration is known here.
            cause = f"coupling iteration {n + 1}: {e}"
            if retry(cause):
                continue
            raise SolverError(cause) from None
        iterations = min(n + 1, coupling.max_iterations)
        report.coupling_iterations += iterations
        report.max_iterations_per_step = max(report.max_iterations_per_step, iterations)
        if not converged:
            if retry("the fixed-stress split did not converge"):
                continue
            report.mean_contraction_ratio = report.ratio_sum / report.ratios if report.ratios else 0.0
            raise CouplingError(f"the fixed-stress split did not converge in {coupling.max_iterations} "
                                f"iterations at t = {t(q):g} (step {K + 1}); last increments:"
                                + "".join(log[-3:]))
        attempts[0] = 0

        # Accept the window: write every fine flow step, then the mechanics step.
        for m in range(1, q + 1):
            flow.set_state(w_new[m])
            on_flow_state(t(m))
        on_mechanics_state(t(q), K + 1, n + 1)
        report.windows = K + 1
        p_K, u_K = p_new[q], u_new
        K += 1
        if stop is not None and stop():
            break
    report.mean_contraction_ratio = report.ratio_sum / report.ratios if report.ratios else 0.0
