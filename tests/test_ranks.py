"""More ranks (issue 24): each path that the rank count changes gives, on 2 ranks,
the 1-rank run's coupling iterations, contact sets and fields (1e-8 relative),
on both tracks: the split with contact (each rank a copy of the factorisation,
PCREDUNDANT, and its share of the contact Schur complement's columns), with
friction on the foundation, the monolithic solve with contact, multirate
windows, adaptive BDF2 steps, and MUMPS across the ranks when named; and `auto`
divides its crossovers by the rank count (the 3D block at [24,12,6]: flow direct
on one rank, iterative on two; the summary says why). A mesh too small for its
ranks (solver.cells_per_rank) is worked by fewer: on 2 ranks fault_reactivation
is the 1-rank run to the bit, summary and log say so, and a failure there ends
both ranks with its status and one line, as does a scene file one rank cannot
see."""
import os
import subprocess
import tempfile

from support import MPI_ENV, PROTOTYPE, ROOT, TRACKS, check, iterations, mpirun, run_track, scene, summary

SHORT = ["time.end=1.2", "mesh.cells=[80,8]"]
CASES = {"split with contact": ([], {"flow": "redundant (lu, petsc on each rank)",
                                     "mechanics": "redundant (cholesky, cholmod on each rank)"}),
         # the cantilever's contact nodes stuck and slipping (mu 0.3: the
         # fields move by 3e-3 from the frictionless run's)
         "split with a frictional foundation": (["boundary.bottom.contact.friction=0.3"], {}),
         "monolithic with contact": (["coupling.scheme=monolithic"],
                                     {"monolithic": "redundant (lu, mumps on each rank)"}),
         # whole windows of q = 4 (1.6 s); BDF2's and the controller's state
         # carried from step to step
         "multirate with contact": (["time.end=1.6", "coupling.scheme=multirate", "coupling.q=4"], {}),
         "adaptive BDF2 with contact": (["time.end=4.8", "time.adaptive.tolerance=1e-2", "time.scheme=bdf2"], {})}


def compare(a, b, label, tolerance="1e-8", claim="2 ranks give the 1-rank run"):
    c = subprocess.run(PROTOTYPE + ["compare", a, b, "--tolerance", tolerance], capture_output=True, text=True,
                       cwd=ROOT, env=MPI_ENV)
    check(c.returncode == 0 and "agree" in c.stdout.splitlines()[-1:]
          and [r["iteration"] for r in iterations(a)] == [r["iteration"] for r in iterations(b)],
          f"{label}: {claim} (fields to {tolerance}, coupling iterations, contact sets)\n{c.stdout[-400:]}")


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

# auto knows the rank count: on 2 ranks the flow's crossover is halved, the
# 3D mechanics' kept (crossover_divisor).
block = ["time.end=0.2", "mesh.cells=[24,12,6]"]
for track in ("C++", "prototype"):
    for ranks, methods in ((1, {"flow": ("direct", 1), "mechanics": ("direct", 1)}),
                           (2, {"flow": ("iterative", 2), "mechanics": ("direct", 1)})):
        out, _ = run_track(track, scene("block3d_box"), *block, ranks=ranks)
        solvers = summary(out)["solvers"]
        check(all(solvers[s]["solver"] == m and f"divided by {d} for {ranks} rank(s)" in solvers[s]["chosen_by"]
                  for s, (m, d) in methods.items()),
              f"{track}, 3D block [24,12,6] on {ranks} rank(s): auto picks {methods} "
              f"({[solvers[s]['chosen_by'] for s in methods]})")
    # One partition per mesh (PT-Scotch on one thread): a second run of the
    # same command on 2 ranks is the first to the bit; with Scotch's threads
    # the partition, and so the iterative flow solve's round-off, changed
    # from run to run (5e-10 in the flux).
    again, _ = run_track(track, scene("block3d_box"), *block, ranks=2)
    compare(out, again, f"{track}, 3D block on 2 ranks twice", "0", "the second run is the first")

# Fewer ranks work than were started: the run of one rank, to the bit.
REACTIVATION = ["--set", "time.end=259200"]


def started_on_two(track, *arguments):
    """A run of fault_reactivation started on 2 ranks with the default
    solver.cells_per_rank; (output directory, completed process)."""
    out = os.path.join(tempfile.mkdtemp(prefix="working-"), "out")
    p = subprocess.run([*mpirun(2), *TRACKS[track], "run", scene("fault_reactivation"), "--out", out, *REACTIVATION,
                        *arguments], capture_output=True, text=True, env=MPI_ENV, cwd=ROOT, timeout=600)
    return out, p


for track in ("C++", "prototype"):
    one, _ = run_track(track, scene("fault_reactivation"), "time.end=259200")
    two, p = started_on_two(track)
    s = summary(two)
    check(p.returncode == 0 and s["mpi_ranks"] == 2 and s["working_ranks"] == 1
          and "1 of 2 ranks works: 4720 cells are fewer than solver.cells_per_rank = 15000" in p.stdout,
          f"{track}: 4,720 cells on 2 ranks: one works, the summary and the log say so "
          f"({s['mpi_ranks']}, {s['working_ranks']}, {p.stderr.strip()[-200:]!r})")
    c = subprocess.run(PROTOTYPE + ["compare", one, two, "--tolerance", "0"], capture_output=True, text=True,
                       cwd=ROOT, env=MPI_ENV)
    check(c.returncode == 0, f"{track}: one working rank of 2 gives the 1-rank run to the bit\n{c.stdout[-300:]}")
    both, p = started_on_two(track, "--set", "solver.cells_per_rank=2000")
    check(p.returncode == 0 and summary(both)["working_ranks"] == 2, f"{track}: cells_per_rank = 2000: both work")
    for status, arguments, says in ((2, ["--out", "/proc/x"], "/proc/x"),
                                    (3, ["-flow_ksp_type", "gmres", "-flow_pc_type", "none", "-flow_ksp_max_it", "1"],
                                     "DIVERGED_ITS")):
        _, p = started_on_two(track, *arguments)
        lines = [line for line in p.stderr.strip().splitlines() if line.startswith("biotcontact")]
        check(p.returncode == status and len(lines) == 1 and says in lines[0],
              f"{track}: a failure while one of 2 ranks waits: exit {p.returncode} == {status}, one line naming "
              f"{says!r} ({p.stderr.strip()[-300:]!r})")

# The scene file seen by one rank only (the other started in another
# directory, as on a node whose file system differs): every rank stops with
# that rank's line (before 2026-12-04 the rank that read it went on and
# waited for ever for the other).
for track in ("C++", "prototype"):
    command = [*TRACKS[track], "run", "scenes/default.toml", "--out", tempfile.mkdtemp(prefix="unseen-")]
    p = subprocess.run([*mpirun(1), "-wdir", ROOT, *command, ":", "-n", "1", "-wdir", tempfile.gettempdir(), *command],
                       capture_output=True, text=True, env=dict(MPI_ENV, PYTHONPATH=ROOT), cwd=ROOT, timeout=300)
    lines = [line for line in p.stderr.strip().splitlines() if line.startswith("biotcontact")]
    check(p.returncode == 2 and lines == ["biotcontact: error: scenes/default.toml: scene file not found"],
          f"{track}: the scene file found by one of 2 ranks only: exit {p.returncode}, one line ({lines})")
