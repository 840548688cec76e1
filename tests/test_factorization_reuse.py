"""Factorisations are reused (issue 9): on the default scene the contact solvers
factorise at most once per inactive-set change (+2), the flow once, and the
fields equal those of the old path (MUMPS LU refactorised at every Newton step)
to 1e-10 relative, for the split and the monolithic solve, with the contact VI
condensed on the Schur complement (the default: one factorisation per operator)
and on the full system. With friction (both tracks, scenes/network2d.toml: 22
frictional fractures): the condensed VI's Jacobian changes only where a pair's
state does (stick, slip or open): factorised anew only then, fewer times than
Newton steps, the fields those of a factorisation at every step to the bit;
iterations.csv's Newton steps (step 0: the initial equilibrium) sum to the
summary's count, the same on both tracks."""
from support import TRACKS, check, iterations, max_difference, run, run_track, scene, summary

FIELDS = ["displacement", "pressure", "flux", "sigma_v", "contact_pressure"]
# The behaviour before issue 9: the VI on the full system, the preconditioner
# rebuilt at every Newton step, MUMPS LU for every system.
OLD = {"mechanics": ["-mechanics_contact_condensed", "false", "-mechanics_snes_lag_preconditioner", "1",
                     "-mechanics_pc_type", "lu", "-mechanics_pc_factor_mat_solver_type", "mumps",
                     "-flow_pc_factor_mat_solver_type", "mumps"],
       "monolithic": ["-monolithic_contact_condensed", "false", "-monolithic_snes_lag_preconditioner", "1",
                      "-monolithic_pc_factor_mat_solver_type", "mumps"]}

for scheme, system in (("fixed-stress", "mechanics"), ("monolithic", "monolithic")):
    old, _ = run(scene("default"), "--set", f"coupling.scheme={scheme}", *OLD[system])
    s_old = summary(old)
    solver_old = s_old["solvers"][system]
    check(solver_old["factorizations"] == solver_old["back_solves"],
          f"{scheme}: the old path factorised at every Newton step ({solver_old['factorizations']})")
    for method, options in (("condensed", []), ("full", [f"-{system}_contact_condensed", "false"])):
        new, _ = run(scene("default"), "--set", f"coupling.scheme={scheme}", *options)
        s = summary(new)
        solver = s["solvers"][system]
        check(method in solver["method"], f"{scheme}, {method}: the method says so ({solver['method']})")
        check(solver["factorizations"] <= solver["active_set_changes"] + 2,
              f"{scheme}, {method}: {solver['factorizations']} factorisations for "
              f"{solver['active_set_changes']} active-set changes ({solver['newton_iterations']} Newton steps)")
        check(solver["factorizations"] < solver_old["factorizations"],
              f"{scheme}, {method}: fewer factorisations than the old path")
        if method == "condensed":
            # The large matrix once (contact DOFs clamped); H from one
            # right-hand side per contact DOF (here, 41 of them), or from
            # one partial factorisation from 400 on (schur_complement.h);
            # two back-solves per solve.
            contact_dofs = s["contact"]["contact_nodes"]
            by_columns = solver["schur_columns"] == contact_dofs and solver["schur_factorizations"] == 0
            by_factorisation = solver["schur_columns"] == 0 and solver["schur_factorizations"] == 1
            check(solver["factorizations"] == 1 and (by_columns or by_factorisation)
                  and solver["back_solves"] == 2 * solver["solves"],
                  f"{scheme}, condensed: 1 factorisation, H from {solver['schur_columns']} Schur columns or "
                  f"{solver['schur_factorizations']} partial factorisation(s) for {contact_dofs} contact DOFs, "
                  f"{solver['back_solves']} back-solves for {solver['solves']} solves")
        if system == "mechanics":
            check(s["solvers"]["flow"]["factorizations"] == 1,
                  f"the flow matrix is factorised once for {s['flow_solves']} solves")
        check(s["coupling_iterations"] == s_old["coupling_iterations"],
              f"{scheme}, {method}: same coupling iterations ({s['coupling_iterations']})")
        differences = max_difference(new, old, FIELDS)
        for name, d in differences.items():
            check(d <= 1e-10, f"{scheme}, {method}: {name} equal to the old path to {d:.1e} relative")


EVERY_STEP = ("-mechanics_contact_snes_lag_preconditioner", "1")
equilibrium = {}
for track in TRACKS:
    runs = {label: run_track(track, scene("network2d"), options=options)[0]
            for label, options in (("reused", ()), ("every step", EVERY_STEP))}
    m = {label: summary(out)["solvers"]["mechanics"] for label, out in runs.items()}
    check(m["every step"]["contact_factorizations"] == m["every step"]["newton_iterations"]
          and 0 < m["reused"]["contact_factorizations"] < m["reused"]["newton_iterations"]
          == m["every step"]["newton_iterations"],
          f"{track}, network2d: {m['reused']['contact_factorizations']} factorisations of the condensed VI for "
          f"{m['reused']['newton_iterations']} Newton steps ({m['every step']['contact_factorizations']} when "
          "factorised at every step)")
    rows = iterations(runs["reused"])
    equilibrium[track] = [(r["iteration"], r["newton_steps"], r["active_nodes"]) for r in rows if r["step"] == "0"]
    steps = sum(int(r["newton_steps"]) for r in rows)
    check(len(equilibrium[track]) == 1 and int(equilibrium[track][0][1]) >= 1
          and steps == m["reused"]["newton_iterations"], f"{track}, network2d: the initial equilibrium is step 0 of "
          f"iterations.csv ({equilibrium[track]}: iteration, Newton steps, active nodes); the rows' {steps} Newton "
          f"steps are the summary's {m['reused']['newton_iterations']}")
    differences = max_difference(runs["reused"], runs["every step"], FIELDS)
    check(max(differences.values()) == 0.0,
          f"{track}, network2d: the fields equal those of a factorisation at every Newton step "
          f"({max(differences.values()):.1e})")
check(equilibrium["C++"] == equilibrium["prototype"], f"network2d: the initial equilibrium's row the same on both "
      f"tracks ({equilibrium['C++']})")
