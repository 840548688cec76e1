"""The iterative solvers (issue 10): with [solver] flow and mechanics =
"iterative" (GMRES + Schur field split with AMG for the flow, CG + GAMG with
the rigid-body modes for the mechanics, the contact VI's Newton steps
preconditioned by AMG on A with the active DOFs held) the fields equal the
direct solve's to 1e-6 relative on the default scene (contact set changing), on
Terzaghi and on the small 3D block, on 1 and 2 ranks; the split on the
iterative path still equals the monolithic solve; linear iterations per solve
do not grow with the mesh; inexact coupling (Krylov tolerances tied to the
coupling increment) saves linear iterations and changes nothing else; a Krylov
solve that fails is one line. FGMRES preconditioned by the fixed-stress split
gives the monolithic factorisation's fields (with and without contact, 1 and 2
ranks) in as many Newton steps (10 % + 2), iterations flat under refinement."""
from support import TRACKS, check, check_signorini, max_difference, run, run_track, scene, summary

FIELDS = ("displacement", "pressure", "flux", "sigma_v")
ITERATIVE = ["--set", "solver.flow=iterative", "--set", "solver.mechanics=iterative"]
DIRECT = ["--set", "solver.flow=direct", "--set", "solver.mechanics=direct"]


def compare(name, extra, fields=FIELDS, ranks=1):
    direct, _ = run(scene(name), *extra, *DIRECT)
    iterative, _ = run(scene(name), *extra, *ITERATIVE, ranks=ranks)
    s = summary(iterative)
    for system in ("flow", "mechanics"):
        check(s["solvers"][system]["solver"] == "iterative" and summary(direct)["solvers"][system]["solver"] == "direct",
              f"{name}, {ranks} rank(s): the summary says {system} was solved iteratively "
              f"({s['solvers'][system]['method']})")
    # sort: the numbering of nodes and cells depends on the partition
    for field, d in max_difference(iterative, direct, fields, sort=ranks > 1).items():
        check(d <= 1e-6, f"{name}, {ranks} rank(s): {field} iterative vs direct {d:.1e} <= 1e-6")
    return direct, iterative


# Default scene: the contact set grows; AMG set up once per inactive set.
direct, iterative = compare("default", [], FIELDS + ("contact_pressure",))
s = summary(iterative)
mechanics = s["solvers"]["mechanics"]
check("full" in mechanics["method"], f"the iterative VI runs on the full system ({mechanics['method']})")
check(mechanics["preconditioner_setups"] <= mechanics["active_set_changes"] + 2,
      f"{mechanics['preconditioner_setups']} AMG set-ups for {mechanics['active_set_changes']} active-set changes")
check(s["solvers"]["flow"]["preconditioner_setups"] == 1, "the flow preconditioner is set up once (one dt)")
counts = check_signorini(iterative, 0.0012, label="iterative ")
check(counts[-1] > counts[1] > 0, f"the contact set grows {counts}")
check(abs(s["coupling_iterations"] - summary(direct)["coupling_iterations"]) <= 2,
      f"same coupling iterations ({s['coupling_iterations']} against {summary(direct)['coupling_iterations']})")

# A block that contact alone holds (elastic_contact, semi-coercive): the
# first Newton step's singular system leaves y far off, and the clamped
# start solves from the held values where y is worse (until 2026-12-05 its
# CG stopped at iteration 0, DIVERGED_DTOL, on both tracks).
for track in TRACKS:
    held, _ = run_track(track, scene("elastic_contact"), "solver.mechanics=direct")
    alone, _ = run_track(track, scene("elastic_contact"), "solver.mechanics=iterative")
    for field, d in max_difference(alone, held, ("displacement", "contact_pressure")).items():
        check(d <= 1e-6, f"elastic_contact ({track}): {field} iterative vs direct {d:.1e} <= 1e-6")

# A Krylov tolerance looser than the contact solve's own: the residual
# decides, not the repeated active set (with -mechanics_ksp_rtol 0.5 the
# set repeated at 4e-4 of the first residual and ended hertz's solve with
# the contact pressure 6 % off and exit 0, both tracks, until 2026-12-05).
for track in TRACKS:
    exact, _ = run_track(track, scene("hertz"))
    loose, _ = run_track(track, scene("hertz"), "solver.mechanics=iterative", options=("-mechanics_ksp_rtol", "0.5"))
    for field, d in max_difference(loose, exact, ("displacement", "contact_pressure")).items():
        check(d <= 1e-6, f"hertz ({track}), -mechanics_ksp_rtol 0.5: {field} against the direct solve {d:.1e} <= 1e-6")

# Inexact coupling (the default on the iterative path): early iterations
# solve to a few digits; fewer Krylov iterations, the same coupling
# iterations and, to the tolerance, the same fields as solves to 1e-10.
exact, _ = run(scene("default"), *ITERATIVE, "--set", "solver.inexact_coupling=false")
s_exact = summary(exact)
for system in ("flow", "mechanics"):
    inexact_its, exact_its = (x["solvers"][system]["linear_iterations"] for x in (s, s_exact))
    check(s["solvers"][system]["inexact_coupling"] and not s_exact["solvers"][system]["inexact_coupling"],
          f"{system}: the summary says whether the coupling was inexact")
    check(inexact_its < exact_its, f"{system}: inexact coupling takes fewer linear iterations "
          f"({inexact_its} against {exact_its})")
check(abs(s["coupling_iterations"] - s_exact["coupling_iterations"]) <= 2,
      f"inexact coupling: same coupling iterations ({s['coupling_iterations']} against {s_exact['coupling_iterations']})")
for field, d in max_difference(iterative, exact, FIELDS).items():
    check(d <= 1e-6, f"inexact against exact solves: {field} {d:.1e} <= 1e-6")

# Two ranks over the first 12 steps (the contact set grows in each of the
# first ones): the whole run took 10-13 s on two ranks beside another test.
SHORT = ["--set", "time.end=2.4"]
compare("default", SHORT, ranks=2)
compare("terzaghi", [])
compare("block3d_box", [])

# The split on the iterative path converges to the monolithic solution.
mono, _ = run(scene("default"), "--set", "coupling.scheme=monolithic")
split, _ = run(scene("default"), *ITERATIVE, "--set", "coupling.tolerance=1e-10",
               "--set", "coupling.max_iterations=400")
for field, d in max_difference(mono, split, ("displacement", "pressure", "flux")).items():
    check(d <= 1e-6, f"iterative split vs monolithic: {field} {d:.1e} <= 1e-6")

# Mesh independence: linear iterations per solve (flow) and per Newton step
# (mechanics) on three levels, two steps each, every solve to 1e-10 (the
# inexact coupling would mix in the coupling's convergence).
per_solve = {"flow": [], "mechanics": []}
for cells in ("[40,4]", "[80,8]", "[160,16]"):
    out, _ = run(scene("default"), *ITERATIVE, "--set", f"mesh.cells={cells}", "--set", "time.end=0.4",
                 "--set", "output.xdmf=false", "--set", "solver.inexact_coupling=false")
    solvers = summary(out)["solvers"]
    per_solve["flow"].append(solvers["flow"]["linear_iterations"] / solvers["flow"]["back_solves"])
    per_solve["mechanics"].append(solvers["mechanics"]["linear_iterations"] / solvers["mechanics"]["newton_iterations"])
for system, its in per_solve.items():
    check(max(its) <= 1.5 * min(its), f"{system}: iterations per solve {[round(i, 1) for i in its]} within 1.5x")

# The monolithic system, FGMRES preconditioned by one fixed-stress sweep,
# against its factorisation: contact (default), none (Terzaghi), 3D.
MONOLITHIC = ["--set", "coupling.scheme=monolithic"]


def compare_monolithic(name, extra=(), ranks=1, same_steps=True):
    direct, _ = run(scene(name), *MONOLITHIC, *extra, "--set", "solver.monolithic=direct")
    iterative, _ = run(scene(name), *MONOLITHIC, *extra, "--set", "solver.monolithic=iterative", ranks=ranks)
    solver = summary(iterative)["solvers"]["monolithic"]
    check(solver["solver"] == "iterative" and "fgmres + fieldsplit" in solver["method"],
          f"monolithic {name}, {ranks} rank(s): solved by {solver['method']}")
    for field, d in max_difference(iterative, direct, ("displacement", "pressure", "flux"), sort=ranks > 1).items():
        check(d <= 1e-6, f"monolithic {name}, {ranks} rank(s): {field} iterative vs direct {d:.1e} <= 1e-6")
    # Balanced rows (docs/theory.md): each step's VI solve goes on from the
    # last solution as the factorisation's does, not from the clamped state
    # (868 Newton steps against 72 on the default scene without them).
    steps = {run: summary(out)["newton_iterations"] for run, out in (("iterative", iterative), ("direct", direct))}
    if same_steps:
        check(steps["iterative"] <= 1.1 * steps["direct"] + 2,
              f"monolithic {name}, {ranks} rank(s): {steps['iterative']} Newton steps, the factorisation's "
              f"{steps['direct']} (at most 10 % + 2 more)")
    return iterative


monolithic = compare_monolithic("default")
check_signorini(monolithic, 0.0012, label="monolithic iterative ")
for field, d in max_difference(monolithic, split, ("displacement", "pressure", "flux")).items():
    check(d <= 1e-6, f"iterative monolithic vs iterative split: {field} {d:.1e} <= 1e-6")
compare_monolithic("default", SHORT, ranks=2)
compare_monolithic("terzaghi")
compare_monolithic("block3d_box", ["--set", "time.end=0.4"])
# Friction (Coulomb, a fault across the body): semismooth, so the Newton
# steps of an inexact Krylov solve are not the factorisation's; without
# balanced rows the first step failed (DIVERGED_LINEAR_SOLVE at 100 steps).
compare_monolithic("fault_reactivation", ["--set", "time.end=259200"], same_steps=False)

# Mesh independence of the fixed-stress preconditioned Krylov method:
# iterations per solve on three levels (Terzaghi: no contact, so every
# solve is one linear solve).
per_solve = []
for cells in ("[4,20]", "[8,40]", "[16,80]"):
    out, _ = run(scene("terzaghi"), *MONOLITHIC, "--set", "solver.monolithic=iterative", "--set",
                 f"mesh.cells={cells}", "--set", "output.xdmf=false")
    solver = summary(out)["solvers"]["monolithic"]
    per_solve.append(solver["linear_iterations"] / solver["back_solves"])
check(max(per_solve) <= 1.5 * min(per_solve),
      f"monolithic: iterations per solve {[round(i, 1) for i in per_solve]} within 1.5x")

# A Krylov method that cannot converge: exit 3, one line naming the system,
# the step and the time.
for system, option in (("mechanics", "-mechanics_ksp_max_it"), ("flow", "-flow_ksp_max_it")):
    out, p = run(scene("default"), *ITERATIVE, option, "1", expect=3)
    lines = p.stderr.strip().splitlines()
    check(len(lines) == 1 and system in lines[0] and "step 1" in lines[0] and "t = 0.2" in lines[0],
          f"{option} 1: one line naming {system}, step and time: {p.stderr.strip()[:200]!r}")
out, p = run(scene("terzaghi"), *MONOLITHIC, "--set", "solver.monolithic=iterative", "-monolithic_ksp_max_it", "1",
             expect=3)
lines = p.stderr.strip().splitlines()
check(len(lines) == 1 and "monolithic" in lines[0] and "step 1" in lines[0],
      f"-monolithic_ksp_max_it 1: one line naming the monolithic system and the step: {p.stderr.strip()[:200]!r}")
