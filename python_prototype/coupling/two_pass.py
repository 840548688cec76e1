"""The second flow pass of the scheme "multirate-two-pass"
(docs/multirate-two-pass.md; cpp/coupling/two_pass.h): after the mechanics,
the window's fine flow steps again without L and with the new displacement,
replacing the fine pressures the mechanics cannot see."""


def second_pass_correction(second, flow, w, history):
    """The printed multirate scheme damps the fine-step pressure modes that
    sum to zero over the window only by L/(S+L) ~ gamma per iteration: the
    mechanics sees p^q alone. Here `second` computes the fine steps again
    without L, from p_K and with u^{n+1},
      (S (p^B_m - p^B_{m-1})/dt, th) + (div z^B_m, th)
        = (Q(t_m), th) - ((alpha/q) div(u^{n+1} - u_K)/dt, th),
    then p^{n+1,m} = p^B_m + (m/q)(p^A_q - p^B_q) (and the same for the
    mixed states): the window end keeps p^A_q, the pressure the mechanics
    used (`flow`, the first pass's step). At the fixed point p^B = p^A: the
    fixed point is that of the printed scheme."""
    q = w.q
    p_B, w_B, fault_B = [history.p_K] * (q + 1), [None] * (q + 1), [w.fault_new[0]] * (q + 1)
    second.u_iterate.x.array[:] = w.u_new
    if flow.fault_aperture is not None:  # conduit faults
        second.take_start_apertures(flow)
    for m in range(1, q + 1):
        history.set_time_history(second, w, m, p_B, w.u_new)
        second.set_fine_step(m, fault_B[m - 1], fault_B[m - 1])  # no L: the iterate is only the guess
        second.solve(history.t(w, m))
        p_B[m] = second.pressure.x.array.copy()
        w_B[m] = second.unknowns().copy()
        fault_B[m] = second.fault_pressure.copy()
    p_end, w_end = w.p_new[q] - p_B[q], w.w_new[q] - w_B[q]
    for m in range(1, q):
        w.p_new[m] = p_B[m] + (m / q) * p_end
        w.w_new[m] = w_B[m] + (m / q) * w_end
        # The conduit faults' pressures are the tail of the mixed states.
        w.fault_new[m] = w.w_new[m][len(w.w_new[m]) - len(w.fault_new[m]):].copy()
