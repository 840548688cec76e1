"""A split that does not converge is an error with the iteration log, and
what was finished before it stays written; with time.retry a step that fails
is tried again with halved steps, and a failure that a smaller step cures no
longer ends the run (split and monolithic, C++ and prototype); a split with
contact that fails without time.retry offers it.

A split that cannot converge says why and what converges instead (issue 36):
with a soft region of gamma near 1 the error, the run's warning and `check`
name gamma, the region where it is reached and the choices (monolithic,
its fallback, Anderson), the same line on both tracks, and the schemes
converge. With coupling.fallback a failed step (a multirate window too) is
the monolithic scheme's, on 2 ranks as on 1 (the coupling tolerance)."""
import os

from support import Fields, check, iterations, run, scene, summary

out, p = run(scene("default"), "--set", "coupling.max_iterations=3", expect=3)
line = p.stderr.strip().splitlines()
check(len(line) == 1 and "did not converge in 3 iterations" in line[0] and "iterations.csv" in line[0],
      f"one-line error naming the log: {p.stderr.strip()[:160]!r}")
# With contact the line also offers time.retry (a step at a contact change or
# an opening that cycles can pass at half the step); without contact not.
check(line[0].endswith('time.retry = 4 (a failed step again with half its dt, up to 4 times) '
                       f'(log: {out}/iterations.csv)'), f"the contact scene's line offers time.retry: {line[0]!r}")
_, p = run(scene("terzaghi"), "--set", "coupling.max_iterations=3", expect=3)
check("did not converge in 3 iterations" in p.stderr and "time.retry" not in p.stderr,
      f"without contact no time.retry: {p.stderr.strip()[-120:]!r}")
rows = iterations(out)
check(len(rows) == 3 and [r["iteration"] for r in rows] == ["1", "2", "3"], "all three iterations logged")
s = summary(out)
check(s["converged"] is False and "failure" in s, "summary says converged = false, with the reason")
check(os.path.exists(os.path.join(out, "solution.xdmf")) and
      Fields(out).times("displacement") == [0.0], "the initial state is written")

# Steps converged before the failing one stay written: the load arrives at
# t = 1 (step 6), the steps before it converge at once, step 6 cannot.
out, p = run(scene("default"), "--set", "coupling.max_iterations=10",
             "--set", "boundary.top.traction=[0.0, '-1e3*(t>1)']", expect=3)
check("at t = 1.2 (step 6)" in p.stderr, f"the failure is in step 6: {p.stderr.strip()[:100]!r}")
s = summary(out)
times = Fields(out).times("displacement")
check(s["steps"] == 5 and len(times) == 6 and abs(times[-1] - 1.0) < 1e-12,
      f"the 5 finished steps are kept (output times {times})")

# time.retry: a failure that a smaller step cures. With the load ramped in
# (contact starts gradually), the contact VI's Newton steps per solve grow
# with the contact nodes that change in one step; capped at 8, step 2
# (t = 0.2 -> 0.4) fails at dt = 0.2 and passes at dt = 0.05.
import subprocess  # noqa: E402

from support import MPI_ENV, ROOT, check_signorini  # noqa: E402

RAMP = ["--set", "mesh.cells=[160,16]", "--set", "time.end=1",
        "--set", "boundary.top.traction=[0.0, '-1e3*min(t/2,1)']"]
for scheme, cap in (("fixed-stress", ["-mechanics_contact_snes_max_it", "8"]),
                    ("monolithic", ["-monolithic_contact_snes_max_it", "6"])):
    case = RAMP + ["--set", f"coupling.scheme={scheme}"] + cap
    out, p = run(scene("default"), *case, expect=3)
    check("step 2 (t = 0.4)" in p.stderr and len(p.stderr.strip().splitlines()) == 1,
          f"{scheme}: without time.retry the ramp fails at step 2 in one line: {p.stderr.strip()[:120]!r}")
    out, p = run(scene("default"), *case, "--set", "time.retry=1", expect=3)
    check(summary(out)["retries"] == 1 and "step 2 (t = 0.3)" in p.stderr,
          f"{scheme}: one retry (dt = 0.1) is not enough, and the failure names the halved step")
    out, p = run(scene("default"), *case, "--set", "time.retry=3")
    s = summary(out)
    check(s["status"] == "completed" and s["retries"] == 2,
          f"{scheme}: with time.retry = 3 the run completes after {s['retries']} retries")
    check("retry 1 of 3 with dt = 0.1" in p.stdout and "retry 2 of 3 with dt = 0.05" in p.stdout,
          f"{scheme}: the log says each retry and its dt")
    times = Fields(out).times("displacement")
    check([round(t, 12) for t in times] == [0.0, 0.2, 0.25, 0.3, 0.4, 0.6, 0.8, 1.0],
          f"{scheme}: step 2 was halved twice, then the steps go on at dt = 0.1 and 0.2 ({times})")
    check_signorini(out, 0.0012, label=f"{scheme} retried ")
    if scheme == "fixed-stress":
        py = out + "-prototype"
        r = subprocess.run(["/usr/bin/python3", "-m", "python_prototype", "run", scene("default"), *case,
                            "--set", "time.retry=3", "--out", py], capture_output=True, text=True,
                           env=dict(MPI_ENV, PYTHONPATH=ROOT), timeout=600)
        c = subprocess.run(["/usr/bin/python3", "-m", "python_prototype", "compare", out, py],
                           capture_output=True, text=True, env=dict(MPI_ENV, PYTHONPATH=ROOT))
        check(r.returncode == 0 and c.returncode == 0 and summary(py)["retries"] == 2,
              "the prototype retries the same steps and agrees with the C++ run")

# coupling.fallback = "monolithic": the split's capped contact solve fails
# step 2, the monolithic scheme (its own solver, uncapped) solves it and the
# split takes steps 3 to 5; capped too, the monolithic solve fails there as
# well: one line with both failures, step 1 kept, summary.json written.
from support import TRACKS, max_difference, run_track  # noqa: E402

FALLBACK = RAMP[1::2] + ["coupling.fallback=monolithic"]
for track in TRACKS:
    out, p = run_track(track, scene("default"), *FALLBACK, options=["-mechanics_contact_snes_max_it", "8"])
    s = summary(out)
    check(s["converged"] and s["steps"] == 5 and s["fallback_steps"] == 1
          and "step 2 (t = 0.4): coupling iteration 1: the contact solver" in p.stdout
          and "the monolithic scheme solves the step (coupling.fallback)" in p.stdout,
          f"{track}: the split's failed step 2 is solved by the monolithic scheme, the run completes "
          f"({s['steps']} steps, {s['fallback_steps']} fallback step)")
    check_signorini(out, 0.0012, label=f"{track} with the fallback ")
    # On 2 ranks the same, to the coupling tolerance 1e-8 (the split's
    # iterates stop at their own partition's): each scheme takes the
    # other's state from the checkpoint kept in memory, each rank's owned
    # values, and the ghosts from their owners (stale ghosts ended the
    # step off, "converged", until 2026-12-04).
    two, _ = run_track(track, scene("default"), *FALLBACK, ranks=2, options=["-mechanics_contact_snes_max_it", "8"])
    fields = max_difference(out, two, ["displacement", "pressure", "contact_pressure"])
    check(summary(two)["fallback_steps"] == 1 and max(fields.values()) <= 1e-8,
          f"{track}: on 2 ranks the fallback's run ends as on 1: {fields} (1e-8)")
    out, p = run_track(track, scene("default"), *FALLBACK, expect=3,
                       options=["-mechanics_contact_snes_max_it", "8", "-monolithic_contact_snes_max_it", "6"])
    line = p.stderr.strip().splitlines()
    s = summary(out)
    check(len(line) == 1 and line[0].startswith("biotcontact: error: step 2 (t = 0.4)")
          and "; the monolithic scheme failed there too (coupling.fallback): the contact solver" in line[0]
          and s["steps"] == 1 and not s["converged"] and s["fallback_steps"] == 0,
          f"{track}: the monolithic solve capped too, one line names both failures, step 1 kept: {line[-1][:330]!r}")

# The multirate schemes fall back too, a window's q fine steps the
# monolithic scheme's steps. Capped, the first window (q = 2, t = 0 to 0.4)
# fails; its fine steps then equal the monolithic run's, which solves the
# same steps from the same start (1e-12), and the split takes the second
# window, on 2 ranks as on 1 (1e-8). "multirate-two-pass" and q = "auto"
# with BDF2 (its history the monolithic steps', WindowHistory.start) the
# same on both tracks (1e-10).
import numpy as np  # noqa: E402

WINDOWS = ["mesh.cells=[160,16]", "time.end=0.8", "boundary.top.traction=[0.0, '-1e3*min(t/2,1)']",
           "coupling.fallback=monolithic", "coupling.scheme=multirate", "coupling.q=2"]
reference, _ = run_track("C++", scene("default"), *WINDOWS[:3], "coupling.scheme=monolithic")
for extra in ([], ["coupling.scheme=multirate-two-pass"], ["coupling.q=auto", "time.scheme=bdf2"]):
    outs = {}
    for track in TRACKS:
        outs[track], p = run_track(track, scene("default"), *WINDOWS, *extra,
                                   options=["-mechanics_contact_snes_max_it", "8"])
        s = summary(outs[track])
        check(s["converged"] and s["fallback_steps"] == 1 and "the monolithic scheme solves the step" in p.stdout,
              f"{track} {extra}: the multirate run completes, one window the monolithic scheme's ({s['steps']} steps)")
        if not extra:
            two, _ = run_track(track, scene("default"), *WINDOWS, ranks=2,
                               options=["-mechanics_contact_snes_max_it", "8"])
            fields = max_difference(outs[track], two, ["displacement", "pressure", "contact_pressure"])
            check(summary(two)["fallback_steps"] == 1 and max(fields.values()) <= 1e-8,
                  f"{track}: on 2 ranks the multirate fallback's run ends as on 1: {fields} (1e-8)")
    fields = max_difference(outs["C++"], outs["prototype"], ["displacement", "pressure", "contact_pressure"])
    check(max(fields.values()) <= 1e-10, f"{extra}: the prototype equals the C++ solver: {fields} (1e-10)")
    if not extra:
        a, b = Fields(reference), Fields(outs["C++"])
        fine = max(np.abs(a.at(name, t) - b.at(name, t)).max() / np.abs(a.at(name, t)).max()
                   for name, times in (("pressure", (0.2, 0.4)), ("displacement", (0.4,))) for t in times)
        check(fine <= 1e-12 and b.times("pressure") == a.times("pressure"),
              f"the failed window's fine steps are the monolithic run's ({fine:.1e}), every fine step written")

# Killed after the window the fallback solved (q = "auto", BDF2: its one
# fine step's history in the checkpoint of step 2) and restarted, the run
# ends as the uninterrupted one to the bit.
import re  # noqa: E402

from support import killed, restarted  # noqa: E402

AFTER = ["mesh.cells=[160,16]", "time.end=1.6", "boundary.top.traction=[0.0, '-1e3*min(t/2,1)']",
         "coupling.fallback=monolithic", "coupling.scheme=multirate", "coupling.q=auto", "time.scheme=bdf2",
         "output.checkpoint_every=2"]
CAP = ["-mechanics_contact_snes_max_it", "8"]
for track in TRACKS:
    whole, _ = run_track(track, scene("default"), *AFTER, options=CAP)
    out = killed(track, scene("default"), 3, *AFTER, options=CAP)
    p = restarted(track, scene("default"), out, *AFTER)
    fields = max_difference(whole, out, ["displacement", "pressure", "contact_pressure"])
    restart = re.search(r"restarted from the checkpoint at step \d+", p.stdout)
    check(summary(whole)["fallback_steps"] == 1 and restart and max(fields.values()) == 0.0,
          f"{track}: killed after step 3, {restart.group(0) if restart else 'not restarted'}: the uninterrupted "
          f"run's fields {fields}")

# Capped harder, with time.retry = 1: the window fails halved too, the
# monolithic scheme solves its first fine step (t = 0.2, written) and fails
# its second halved too, its retry named as its own: one line with both
# failures, no step completed.
for track in TRACKS:
    out, p = run_track(track, scene("default"), *WINDOWS, "time.retry=1", expect=3,
                       options=["-mechanics_contact_snes_max_it", "2", "-monolithic_contact_snes_max_it", "6"])
    line = p.stderr.strip().splitlines()
    check(len(line) == 1 and "the monolithic scheme failed there too (coupling.fallback)" in line[0]
          and "the monolithic scheme: step 2 failed" in p.stdout and summary(out)["steps"] == 0
          and Fields(out).times("pressure") == [0.0, 0.2],
          f"{track}: the fallback's monolithic scheme fails a fine step after its retry: {line[-1][:200]!r}")

# With time.adaptive the fallback solves the failed step and the control
# goes on from it (a rejected step later, 8 steps); the monolithic scheme
# stops at or past the step's end, as the control's steps may pass it.
ADAPTIVE = FALLBACK + ["time.adaptive={tolerance=1e-1}"]
outs = {}
for track in TRACKS:
    outs[track], _ = run_track(track, scene("default"), *ADAPTIVE, options=["-mechanics_contact_snes_max_it", "8"])
    s = summary(outs[track])
    check(s["converged"] and s["fallback_steps"] == 1 and s["steps"] == 8 and s["adaptive"]["rejected_steps"] == 1,
          f"{track}: time.adaptive with the fallback completes ({s['steps']} steps, {s['fallback_steps']} fallback)")
fields = max_difference(outs["C++"], outs["prototype"], ["displacement", "pressure", "contact_pressure"])
check(max(fields.values()) <= 1e-10, f"time.adaptive with the fallback: the prototype equals the C++ solver: {fields}")

# A multirate run that fails proposes the fallback: the restart from its
# checkpoint cannot change its scheme (restart_fingerprint), and the
# restart with coupling.fallback goes on (before 2026-12-05 it proposed
# "--set coupling.scheme=monolithic", which the restart refused).
LATE = ["coupling.scheme=multirate", "coupling.q=2", "coupling.max_iterations=10",
        "boundary.top.traction=[0.0, '-1e3*(t>1)']", "output.checkpoint_every=1"]
for track in TRACKS:
    out, p = run_track(track, scene("default"), *LATE, expect=3)
    line = p.stderr.strip().splitlines()
    proposal = 'coupling.fallback = "monolithic" (that scheme for the steps the split fails at)'
    check(len(line) == 1 and proposal in line[0]
          and f"step 2 is in the checkpoint (--restart {out} --set coupling.fallback=monolithic goes on from it)"
          in line[0], f"{track}: the multirate run's failure proposes its fallback: {line[-1][-200:]!r}")
    restarted(track, scene("default"), out, *LATE, "coupling.fallback=monolithic")
    s = summary(out)
    check(s["converged"] and s["fallback_steps"] > 0,
          f"{track}: restarted with coupling.fallback it completes ({s['steps']} steps, {s['fallback_steps']} "
          "fallback)")

# With time.scheme = "bdf2" the split takes over from the monolithic
# scheme, whose history has no displacement_path_before: with one fine step
# a window it is the displacement one step before. Until 2026-12-05 the
# fallback, and a restart of a monolithic run's checkpoint as the split,
# ended "--restart OUT: the checkpoint does not match this mesh", and the
# restart, its window_q unset, a NaN tolerance. Both now end as the
# monolithic run within 1e-6: the split from the start is 4.6e-8 from it
# (tolerance 1e-8 at gamma 0.97), a history one step off 8e-2.
MONOLITHIC_BDF2 = RAMP[1::2] + ["time.scheme=bdf2", "coupling.scheme=monolithic"]
for track in TRACKS:
    reference, _ = run_track(track, scene("default"), *MONOLITHIC_BDF2)
    fell_back, _ = run_track(track, scene("default"), *FALLBACK, "time.scheme=bdf2",
                             options=["-mechanics_contact_snes_max_it", "8"])
    restart, _ = run_track(track, scene("default"), *MONOLITHIC_BDF2, "output.checkpoint_every=1", expect=3,
                           options=["-monolithic_contact_snes_max_it", "6"])
    restarted(track, scene("default"), restart, *RAMP[1::2], "time.scheme=bdf2", "output.checkpoint_every=1",
              "coupling.scheme=fixed-stress")
    for name, out in (("the fallback", fell_back), ("the split restarted from step 1", restart)):
        fields = max_difference(reference, out, ["displacement", "pressure", "contact_pressure"])
        check(summary(out)["steps"] == 5 and summary(out)["converged"] and max(fields.values()) <= 1e-6,
              f"{track}, BDF2: {name} ends as the monolithic run: {fields} (1e-6)")
    check(summary(fell_back)["fallback_steps"] == 1, f"{track}, BDF2: one fallback step")

# A soft region (E = 1e5 Pa in x < 5): gamma = alpha^2/(alpha^2 + lambda S)
# there, with lambda = E nu/((1 + nu)(1 - 2 nu)) and S = 1/M + c_f phi0 of
# the default scene, is 0.9999973; the split does not converge in 1000
# iterations with either L. The error names gamma, the region and what
# converges instead; both tracks print the same line.

SOFT = ["region.soft.where=x < 5", "region.soft.E=1.0e5"]
E, nu, M, c_f, phi0 = 1.0e5, 0.2, 1.0e11, 4.4e-10, 0.2
gamma = 1 / (1 + E * nu / ((1 + nu) * (1 - 2 * nu)) * (1 / M + c_f * phi0))
NAMED = [f"gamma = {gamma:.7g} in region soft > 0.99", 'coupling.scheme = "monolithic"',
         'coupling.fallback = "monolithic"']
ANDERSON = 'coupling.acceleration = "anderson"'
for L in ("paper", "kdr"):
    errors = {}
    for track in TRACKS:
        _, p = run_track(track, scene("default"), *SOFT, f"coupling.L={L}", expect=3)
        errors[track] = p.stderr.strip().rsplit(" (log:", 1)[0]
        check(len(p.stderr.strip().splitlines()) == 1 and "did not converge in 1000 iterations" in errors[track]
              and all(n in errors[track] for n in NAMED + [ANDERSON]),
              f"{track}, L = {L}: the error names gamma, the region and the choices: {errors[track][-330:]!r}")
    check(errors["C++"] == errors["prototype"], f"L = {L}: the same error on both tracks")
# The warning of the run and of `check` names the same, Anderson only where
# it is not on already; the choices it names converge.
for track, command in TRACKS.items():
    for acceleration in ("none", "anderson"):
        sets = [a for s in SOFT + [f"coupling.acceleration={acceleration}"] for a in ("--set", s)]
        c = subprocess.run([*command, "check", scene("default"), *sets], capture_output=True, text=True,
                           env=MPI_ENV, cwd=ROOT, timeout=300)
        warning = [line for line in c.stdout.splitlines() if line.startswith("warning: gamma")]
        check(c.returncode == 0 and len(warning) == 1 and all(n in warning[0] for n in NAMED)
              and (ANDERSON in warning[0]) == (acceleration == "none"),
              f"{track}, acceleration {acceleration}: `check` warns, naming gamma, the region and the choices "
              f"({warning!r})")
    plain = subprocess.run([*command, "check", scene("default")], capture_output=True, text=True, env=MPI_ENV,
                           cwd=ROOT, timeout=300)
    check(plain.returncode == 0 and "warning" not in plain.stdout, f"{track}: no warning at the default gamma 0.973")
    for choice in ("coupling.acceleration=anderson", "coupling.scheme=monolithic"):
        out, p = run_track(track, scene("default"), *SOFT, choice)
        warned = [line for line in p.stdout.splitlines() if line.startswith("warning: gamma")]
        check(summary(out)["status"] == "completed" and len(warned) == (choice != "coupling.scheme=monolithic"),
              f"{track}, {choice}: the run completes ({summary(out)['coupling_iterations']} coupling iterations), "
              f"warned {len(warned)} time(s)")
