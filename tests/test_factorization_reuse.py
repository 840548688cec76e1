"""Factorisations are reused (issue 9): on the default scene the contact
solvers factorise at most once per inactive-set change (+2), the flow once,
and the fields equal those of the old path (MUMPS LU refactorised at every
Newton step) to 1e-10 relative, for the split and the monolithic solve."""
from support import check, max_difference, run, scene, summary

FIELDS = ["displacement", "pressure", "flux", "sigma_v", "contact_pressure"]
# The behaviour before issue 9: rebuild the preconditioner at every Newton
# step, MUMPS LU for every system.
OLD = {"fixed-stress": ["-mechanics_snes_lag_preconditioner", "1", "-mechanics_pc_type", "lu",
                        "-mechanics_pc_factor_mat_solver_type", "mumps",
                        "-flow_pc_factor_mat_solver_type", "mumps"],
       "monolithic": ["-monolithic_snes_lag_preconditioner", "1",
                      "-monolithic_pc_factor_mat_solver_type", "mumps"]}

for scheme, system in (("fixed-stress", "mechanics"), ("monolithic", "monolithic")):
    new, _ = run(scene("default"), "--set", f"coupling.scheme={scheme}")
    old, _ = run(scene("default"), "--set", f"coupling.scheme={scheme}", *OLD[scheme])
    s, s_old = summary(new), summary(old)
    solver, solver_old = s["solvers"][system], s_old["solvers"][system]
    check(solver["factorizations"] <= solver["active_set_changes"] + 2,
          f"{scheme}: {solver['factorizations']} factorisations for {solver['active_set_changes']} "
          f"active-set changes ({solver['back_solves']} Newton steps)")
    check(solver_old["factorizations"] == solver_old["back_solves"] > solver["factorizations"],
          f"{scheme}: the old path factorised at every Newton step ({solver_old['factorizations']})")
    if system == "mechanics":
        check(s["solvers"]["flow"]["factorizations"] == 1,
              f"the flow matrix is factorised once for {s['flow_solves']} solves")
    check(s["coupling_iterations"] == s_old["coupling_iterations"],
          f"{scheme}: same coupling iterations ({s['coupling_iterations']})")
    differences = max_difference(new, old, FIELDS)
    for name, d in differences.items():
        check(d <= 1e-10, f"{scheme}: {name} equal to the old path to {d:.1e} relative")
