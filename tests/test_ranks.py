"""More ranks (issue 24): each path that the rank count changes gives, on 2
ranks, the 1-rank run's coupling iterations, contact sets and fields (1e-8
relative), on both tracks:
- the split with contact, where each rank holds a copy of the one-rank
  factorisation (PCREDUNDANT: CHOLMOD, PETSc's LU) and forms its share of
  the contact Schur complement's columns;
- the monolithic solve with contact (MUMPS on each rank's copy);
- a factorisation across the ranks when the command line names it
  (MUMPS, the Schur complement's columns as distributed solves);
and `auto` divides its crossovers by the rank count: the 3D block at
[24,12,6] (32,112 flow and 6,825 mechanics unknowns) has its flow solved
directly on one rank and iteratively on two (crossover 5e4, 2.5e4 on two),
its mechanics directly on both (3e4, 1.5e4), and the summary says why."""
import subprocess

from support import MPI_ENV, PROTOTYPE, ROOT, check, iterations, run_track, scene, summary

SHORT = ["time.end=1.2", "mesh.cells=[80,8]"]
CASES = {"split with contact": ([], {"flow": "redundant (lu, petsc on each rank)",
                                     "mechanics": "redundant (cholesky, cholmod on each rank)"}),
         "monolithic with contact": (["coupling.scheme=monolithic"],
                                     {"monolithic": "redundant (lu, mumps on each rank)"})}


def compare(a, b, label):
    c = subprocess.run(PROTOTYPE + ["compare", a, b, "--tolerance", "1e-8"], capture_output=True, text=True,
                       cwd=ROOT, env=MPI_ENV)
    check(c.returncode == 0 and [r["iteration"] for r in iterations(a)] == [r["iteration"] for r in iterations(b)],
          f"{label}: 2 ranks give the 1-rank run (fields to 1e-8, coupling iterations, contact sets)\n"
          f"{c.stdout[-400:]}")


def counts(out):
    return {name: (s.get("factorizations"), s.get("schur_columns")) for name, s in summary(out)["solvers"].items()}


for track in ("C++", "prototype"):
    for label, (sets, methods) in CASES.items():
        one, _ = run_track(track, scene("default"), *SHORT, *sets)
        two, _ = run_track(track, scene("default"), *SHORT, *sets, ranks=2)
        compare(one, two, f"{track}, {label}")
        used = summary(two)["solvers"]
        check(all(text in used[system]["method"] for system, text in methods.items()),
              f"{track}, {label}: each rank factorises a copy ({[s['method'] for s in used.values()]})")
        check(counts(one) == counts(two), f"{track}, {label}: the same factorisations and Schur complement "
              f"columns on 1 and 2 ranks ({counts(one)}, {counts(two)})")

# A factorisation across the ranks, named on the command line.
across = ["-mechanics_pc_type", "cholesky", "-mechanics_pc_factor_mat_solver_type", "mumps"]
one, _ = run_track("C++", scene("default"), *SHORT)
two, _ = run_track("C++", scene("default"), *SHORT, ranks=2, options=across)
compare(one, two, "C++, MUMPS across the ranks (named)")
check("cholesky (mumps)" in summary(two)["solvers"]["mechanics"]["method"],
      f"MUMPS across the ranks when named ({summary(two)['solvers']['mechanics']['method']})")

# auto knows the rank count.
block = ["time.end=0.2", "mesh.cells=[24,12,6]"]
for track in ("C++", "prototype"):
    for ranks, methods in ((1, {"flow": "direct", "mechanics": "direct"}),
                           (2, {"flow": "iterative", "mechanics": "direct"})):
        out, _ = run_track(track, scene("block3d_box"), *block, ranks=ranks)
        solvers = summary(out)["solvers"]
        check(all(solvers[s]["solver"] == m and f"divided by {ranks} rank(s)" in solvers[s]["chosen_by"]
                  for s, m in methods.items()),
              f"{track}, 3D block [24,12,6] on {ranks} rank(s): auto picks {methods} "
              f"({[solvers[s]['chosen_by'] for s in methods]})")
