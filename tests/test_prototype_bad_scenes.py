"""Bad input to the Python prototype gets the C++ solver's one-line error
(same key named, same text) and exit status 2; a split that does not
converge gets the same error and exit status 3 in both."""
import json
import os
import subprocess
import tempfile

from support import (BINARY, MPI_ENV, ROOT, PrototypeWorker, check, crack_scenes, fault_group_scenes, flow_crack_scene,
                     foundation_fault_scene, scene)

PROTOTYPE = ["/usr/bin/python3", "-m", "python_prototype"]
ENV = dict(MPI_ENV, PYTHONPATH=ROOT)
DEFAULT = scene("default")
WORKER = PrototypeWorker()


def both(command, path, overrides, extra=()):
    """(exit status, stderr) of the C++ solver and of the prototype (its
    command line run in one process for all cases: PrototypeWorker)."""
    args = [command, path] + [a for o in overrides for a in ("--set", o)] + list(extra)
    if command == "run" and "--out" not in extra:
        args += ["--out", tempfile.mkdtemp()]
    p = subprocess.run([BINARY] + args, capture_output=True, text=True, env=ENV, timeout=300)
    status, stderr = WORKER.run(args)
    return [(p.returncode, p.stderr.strip()), (status, stderr.strip())]


CASES = [
    ("unknown key", ["mechanics.Ee=1.0"], "mechanics.Ee"),
    ("nu = 0.5", ["mechanics.nu=0.5"], "mechanics.nu"),
    ("end not a multiple of dt", ["time.dt=0.7"], "time.dt"),
    ("q without multirate", ["coupling.q=2"], "coupling.q"),
    ("two-pass multirate without storage", ["coupling.scheme=multirate-two-pass", "flow.M=inf", "flow.c_f=0.0"],
     "coupling.scheme"),
    ("unknown boundary name", ["boundary.middle.pressure=0.0"], "boundary.middle"),
    ("bad expression", ["boundary.top.pressure='x +* 2'"], "boundary.top.pressure"),
    ("unknown L", ["coupling.L=optimal"], "coupling.L"),
    ("negative gap where evaluated", ["boundary.bottom.contact.gap='x-5'"], "boundary.bottom.contact.gap"),
    ("zero normal", ["boundary.bottom.contact.normal=[0, 0]"], "boundary.bottom.contact.normal"),
    ("a foundation normal into the body", ["boundary.bottom.contact.normal=[0.0, 1.0]"],
     "boundary.bottom.contact.normal"),
    ("a normal NaN where evaluated", ["boundary.bottom.contact.normal=['0', '-sqrt(x-5)']"],
     "boundary.bottom.contact.normal"),
    ("opposite normals at a node evaluated", ["boundary.right.contact={ gap = 0.1, normal = [0.0, 1.0] }"],
     "contact.normal"),
    ("NaN traction", ["boundary.top.traction=['0', 'sqrt(-1)']"], "boundary.top.traction"),
    ("infinite source", ["flow.source='1/(x-x)'"], "flow.source"),
    ("a region without where", ["region.r.E=2e9"], "region.r.where"),
    ("two regions that claim one cell", ["region.a.where='x < 6'", "region.b.where='x > 4'"], "region.b"),
    ("a region that holds no cell", ["region.r.where='x > 100'"], "region.r"),
    ("an unknown region key", ["region.r.where='x > 5'", "region.r.mu_f=1e-3"], "region.r.mu_f"),
    ("a region permeability zero at some cells", ["region.r.where='x > 5'", "region.r.permeability='1e-13*(x-7)'"],
     "region.r.permeability"),
    ("NaN initial pressure", ["flow.initial_pressure='log(x-100)'"], "flow.initial_pressure"),
    ("3e9 steps", ["time.end=3e9", "time.dt=1"], "time.dt"),
    ("a mesh larger than the machine", ["mesh.cells=[4000000, 4000000]"], "mesh.cells"),
    ("unknown solver choice", ["solver.flow=gpu"], "solver.flow"),
    ("negative cells per rank", ["solver.cells_per_rank=-1"], "solver.cells_per_rank: must be >= 0"),
    ("unknown acceleration", ["coupling.acceleration=aitken"], "coupling.acceleration"),
    ("Anderson depth 0", ["coupling.acceleration=anderson", "coupling.depth=0"], "coupling.depth"),
    ("unknown fallback", ["coupling.fallback=newton"], "coupling.fallback"),
    ("mistyped pin_cycles", ["coupling.pin_cycles=1"], "coupling.pin_cycles"),
    ("negative checkpoint interval", ["output.checkpoint_every=-1"], "output.checkpoint_every"),
    ("zero progress interval", ["output.progress_interval=0"], "output.progress_interval"),
    ("infinite progress interval", ["output.progress_interval=inf"], "output.progress_interval"),
]
for label, overrides, key in CASES:
    command = "run" if label.endswith("evaluated") else "check"  # the gap is evaluated at the nodes in a run
    (cs, ce), (ps, pe) = both(command, DEFAULT, overrides)
    check(ps == 2 and cs == 2, f"{label}: exit status 2 (C++ {cs}, prototype {ps})")
    check(len(pe.splitlines()) == 1 and key in pe and pe == ce,
          f"{label}: the prototype's one line equals the C++ one: {pe!r}")

for label, extra, key in (("unknown --option", ["--foo"], "--foo"),
                          ("no bounds in the contact solver", ["-mechanics_snes_type", "newtonls"],
                           "-mechanics_snes_type"),
                          ("a relative tolerance of 1 or more", ["-mechanics_snes_rtol", "2"],
                           "-mechanics_snes_rtol 2"),
                          ("a line search the contact solver cannot take",
                           ["-mechanics_snes_linesearch_type", "nleqerr"], "-mechanics_snes_linesearch_type nleqerr"),
                          ("preonly without a factorisation", ["-flow_ksp_type", "preonly", "-flow_pc_type", "none"],
                           "-flow_ksp_type preonly"),
                          ("no inactive set for the iterative contact solver",
                           ["--set", "solver.mechanics=iterative", "-mechanics_snes_type", "vinewtonssls"],
                           "-mechanics_snes_type vinewtonssls"),
                          ("contact_condensed not a boolean", ["-mechanics_contact_condensed", "maybe"],
                           "-mechanics_contact_condensed"),
                          ("an output directory that cannot be made", ["--out", "/proc/x"], "/proc/x")):
    (cs, ce), (ps, pe) = both("run", DEFAULT, [], extra)
    check(ps == cs == 2 and len(pe.splitlines()) == 1 and key in pe and pe == ce,
          f"{label}: the same line and status 2 (C++ {cs}, prototype {ps}): {pe!r}")

(cs, ce), (ps, pe) = both("check", scene("hertz"), ["region.rock.E=2e9"])
check(ps == cs == 2 and len(pe.splitlines()) == 1 and "region.rock" in pe and pe == ce,
      f"a region that is no group of the gmsh file: the same line and status 2: {pe!r}")

# Faults (issue 37) and a given pore pressure: the same line on both tracks,
# on the scenes the catalogue (test_bad_scenes.py) refuses them in.
for label, path, overrides, key in (
        ("a fault on a built-in mesh", DEFAULT, ["fault.f.gap=0.0"], "fault.f"),
        ("a fault that is also a boundary", scene("hertz"), ["fault.top.gap=0.0"], "fault.top"),
        ("a fault gap that depends on t", scene("hertz"), ["fault.f.gap='1e-3*t'"], "fault.f.gap"),
        ("a fault with pressure and pore_pressure_load", scene("fracture"),
         ["fault.f.pressure=1e5", "fault.f.pore_pressure_load=true"], "fault.f.pore_pressure_load"),
        ("a fault pore pressure load without a pore pressure", scene("hertz"), ["fault.f.pore_pressure_load=true"],
         "fault.f.pore_pressure_load"),
        ("an unknown fault flow", scene("hertz"), ["fault.f.flow=leaky"], "fault.f.flow"),
        ("a sealing fault without flow", scene("hertz"), ["fault.f.flow=sealing"], "fault.f.flow"),
        ("a fault held at no pressure", scene("fracture"), ["fault.f.flow=pressure"], "fault.f.pressure"),
        ("a zero fault normal", scene("hertz"), ["fault.f.normal=[0, 0]"], "fault.f.normal"),
        ("an infinite fault normal", scene("hertz"), ["fault.f.normal=[inf, 1]"], "fault.f.normal"),
        ("a fault normal of the wrong length", scene("hertz"), ["fault.f.normal=[0, 0, 1]"], "fault.f.normal"),
        ("an unknown fault key", scene("hertz"), ["fault.f.aperture=1e-3"], "fault.f.aperture"),
        ("a fault that is no table", scene("hertz"), ["fault.f=1"], "fault.f"),
        ("a given pore pressure with flow", DEFAULT, ["mechanics.pore_pressure=1e5", "mechanics.alpha=1.0"],
         "mechanics.pore_pressure"),
        ("a given pore pressure without alpha", scene("elastic_contact"), ["mechanics.pore_pressure=1e5"],
         "mechanics.alpha"),
        ("mechanics.alpha without a given pore pressure", scene("elastic_contact"), ["mechanics.alpha=0.8"],
         "mechanics.alpha"),
        ("mechanics.alpha = 0", scene("elastic_contact"), ["mechanics.pore_pressure=1e5", "mechanics.alpha=0.0"],
         "mechanics.alpha"),
        ("mechanics.alpha > 1", scene("elastic_contact"), ["mechanics.pore_pressure=1e5", "mechanics.alpha=1.5"],
         "mechanics.alpha"),
        ("a NaN given pore pressure", scene("elastic_contact"),
         ["mechanics.pore_pressure='sqrt(-1-x)'", "mechanics.alpha=1.0"], "mechanics.pore_pressure"),
        ("an infinite given pore pressure at the end", scene("elastic_contact"),
         ["mechanics.pore_pressure='1e5/(t-1)'", "mechanics.alpha=1.0"], "mechanics.pore_pressure"),
        ("a pore pressure load without a pore pressure", scene("elastic_contact"),
         ["boundary.bottom.pore_pressure_load=true"], "boundary.bottom.pore_pressure_load")):
    (cs, ce), (ps, pe) = both("check", path, overrides)
    check(ps == cs == 2 and len(pe.splitlines()) == 1 and key in pe and pe == ce,
          f"{label}: the same line and status 2 (C++ {cs}, prototype {ps}): {pe!r}")

# The faults' bad inputs of the split mesh and the flow: the catalogue's
# scenes; the pairs are made by `check` too (a negative gap, a fault on a foundation).
CRACK_GEO, CRACK, DEGENERATE = crack_scenes()  # CRACK: the .geo meshed once
LOOSE, SHARED, PINNED = fault_group_scenes()
FLOW_CRACK = flow_crack_scene()
for label, command, path, overrides, key in (
        ("a fault group that does not exist", "check", CRACK, ["fault.nowhere.gap=0.0"], "fault.nowhere"),
        ("a fault group of the wrong dimension", "check", CRACK, ["fault.rock.gap=0.0"], "fault.rock"),
        ("a fault group on the outer boundary", "check", CRACK, ["fault.top.gap=0.0"], "fault.top"),
        ("faults that meet where a displacement is prescribed", "check", PINNED, [], "is not perpendicular to the faults"),
        ("a fault curve not embedded in the surface", "check", LOOSE, [], "Curve{..} In Surface{..}"),
        ("one curve in two faults' groups", "check", SHARED, [], "the physical groups crack and other share"),
        ("a fault array of the mesh's other dimension", "check", CRACK, ["fault.crack.normal=[0.0, 1.0, 0.0]"],
         "one per axis (mesh.dimension = 2)"),
        ("names that refer to one another", "check", CRACK, ["expressions.a='b'", "expressions.b='2*a'"],
         "cycle (a -> b -> a)"),
        ("a name that is a function", "check", CRACK, ["expressions.sqrt=2.0"], "expressions.sqrt"),
        ("a named expression that does not parse", "check", CRACK, ["expressions.a='1 + * 2'"], "expressions.a"),
        ("E an expression of x", "check", CRACK, ["mechanics.E='1e9*(1 + x)'"], "mechanics.E"),
        ("E an expression that is NaN", "check", CRACK, ["mechanics.E='sqrt(-1)'"], "gives NaN"),
        ("a conduit fault with a pressure", "check", FLOW_CRACK,
         ["fault.crack.flow=conduit", "fault.crack.residual_aperture=1e-4", "fault.crack.pressure=1e6"],
         "fault.crack.pressure"),
        ("a conduit fault loaded by the pore pressure", "check", FLOW_CRACK,
         ["fault.crack.flow=conduit", "fault.crack.residual_aperture=1e-4", "fault.crack.pore_pressure_load=true"],
         "fault.crack.pore_pressure_load"),
        ("a negative fault gap", "check", CRACK, ["fault.crack.gap=-1e-3"], "fault.crack.gap"),
        ("a negative tip size", "check", CRACK_GEO, ["fault.crack.tip_size=-0.01"], "fault.crack.tip_size"),
        ("a tip grading without a tip size", "check", CRACK_GEO, ["fault.crack.tip_grading=0.3"],
         "fault.crack.tip_grading"),
        ("a tip size on a .geo with size fields of its own", "check", CRACK_GEO, ["fault.crack.tip_size=0.01"],
         "fault.crack.tip_size"),
        ("a fault that reaches a contact boundary", "check", foundation_fault_scene(), [], "fault.fault"),
        ("a fault pressure that is NaN", "check", CRACK, ["fault.crack.pressure='sqrt(x - 10)'"],
         "fault.crack.pressure"),
        ("a degenerate cell", "check", DEGENERATE, [], "degenerate.geo"),
        ("a negative friction", "check", CRACK, ["fault.crack.friction=-0.1"], "fault.crack.friction"),
        ("a negative cohesion", "check", CRACK, ["fault.crack.cohesion=-1.0"], "fault.crack.cohesion"),
        ("a Tresca bound with friction", "check", CRACK, ["fault.crack.tresca=1e6", "fault.crack.friction=0.3"],
         "fault.crack.tresca"),
        ("friction on a boundary without contact", "check", CRACK, ["boundary.left.friction=0.3"],
         "boundary.left.friction"),
        ("friction where two foundations meet", "run", scene("groove"), ["boundary.left_flank.contact.friction=0.3"],
         "boundary.left_flank.contact.friction"),
        ("a zero residual aperture", "check", FLOW_CRACK,
         ["fault.crack.flow=conduit", "fault.crack.residual_aperture=0.0"], "fault.crack.residual_aperture"),
        ("a negative normal permeability", "check", FLOW_CRACK,
         ["fault.crack.flow=conduit", "fault.crack.residual_aperture=1e-4", "fault.crack.normal_permeability=-1.0"],
         "fault.crack.normal_permeability"),
        ("a fault permeability on a fault that is no conduit", "check", FLOW_CRACK,
         ["fault.crack.permeability=1e-10"], "fault.crack.permeability"),
        ("a negative fault permeability", "check", FLOW_CRACK,
         ["fault.crack.flow=conduit", "fault.crack.residual_aperture=1e-4", "fault.crack.permeability=-1e-10"],
         "fault.crack.permeability"),
        ("a zero largest closure", "check", scene("fault_reactivation"),
         ["fault.fault.flow=conduit", "fault.fault.residual_aperture=1e-4", "fault.fault.pore_pressure_load=false",
          "fault.fault.closure={ V_m = 0.0, K_ni = 1e10 }"], "fault.fault.closure.V_m"),
        ("a well off its fault", "check", FLOW_CRACK,
         ["fault.crack.flow=conduit", "fault.crack.residual_aperture=1e-4", "well.inj.position=[0.0, 5.0]",
          "well.inj.rate=1e-6", "well.inj.fault=crack"], "well.inj.position"),
        ("a conduit fault with BDF2 and a multirate scheme", "check", scene("fault_reactivation"),
         ["fault.fault.flow=conduit", "fault.fault.residual_aperture=1e-4", "fault.fault.pore_pressure_load=false",
          'time.scheme="bdf2"', 'coupling.scheme="multirate"'],
         "fault.fault.flow")):
    (cs, ce), (ps, pe) = both(command, path, overrides)
    check(ps == cs == 2 and len(pe.splitlines()) == 1 and key in pe and pe == ce,
          f"{label}: the same line and status 2 (C++ {cs}, prototype {ps}): {pe!r}")

(cs, ce), (ps, pe) = both("check", os.path.join(ROOT, "no", "such.toml"), [])
check(ps == cs == 2 and pe == ce, f"missing scene file: same line and status 2: {pe!r}")

# `compare`, the prototype's own command: a directory that is no run, a
# tolerance that is no number, a damaged solution.xdmf: one line naming
# the cause, status 2, no traceback.
empty, damaged = tempfile.mkdtemp(), tempfile.mkdtemp()
with open(os.path.join(damaged, "iterations.csv"), "w") as f:
    f.write("step,iteration\n")
with open(os.path.join(damaged, "solution.xdmf"), "w") as f:
    f.write("<Xdmf")
for label, args, key in (("a directory that is no run", [empty, damaged], "solution.xdmf: not found"),
                         ("a tolerance that is no number", [damaged, damaged, "--tolerance", "x"], "--tolerance"),
                         ("a damaged solution.xdmf", [damaged, damaged], "cannot read the runs")):
    p = subprocess.run(PROTOTYPE + ["compare"] + args, capture_output=True, text=True, env=ENV, timeout=120)
    lines = p.stderr.strip().splitlines()
    check(p.returncode == 2 and len(lines) == 1 and lines[0].startswith("biotcontact: error:") and key in lines[0],
          f"compare, {label}: one line naming {key!r}, status 2 (status {p.returncode}): {p.stderr.strip()!r}")

(cs, ce), (ps, pe) = both("run", DEFAULT, ["coupling.max_iterations=3"])
check(ps == cs == 3, f"non-convergence: exit status 3 (C++ {cs}, prototype {ps})")
strip = [e.rsplit(" (log:", 1)[0] for e in (ce, pe)]
check(strip[0] == strip[1] and "did not converge in 3 iterations" in pe,
      f"non-convergence: the same message: {pe[:120]!r}")

# A solver that fails before step 1 (the initial equilibrium): exit 3, one
# line, and summary.json written all the same (issue 50: every exit 3).
for exe, name in (([BINARY], "C++"), (PROTOTYPE, "prototype")):
    out = tempfile.mkdtemp()
    p = subprocess.run(exe + ["run", scene("fault_reactivation"), "--out", out, "--set", "solver.mechanics=iterative",
                              "-mechanics_ksp_max_it", "1"], capture_output=True, text=True, env=ENV, timeout=300)
    lines = p.stderr.strip().splitlines()
    written = os.path.exists(os.path.join(out, "summary.json"))
    status = json.load(open(os.path.join(out, "summary.json")))["status"] if written else None
    check(p.returncode == 3 and len(lines) == 1 and "initial equilibrium" in lines[0] and status == "failed",
          f"{name}: the initial equilibrium fails: exit {p.returncode} (3), one line naming it, summary.json "
          f"status {status!r} ('failed'): {p.stderr.strip()[:160]!r}")

(cs, ce), (ps, pe) = both("run", DEFAULT, [], ["-flow_ksp_type", "gmres", "-flow_pc_type", "none",
                                               "-flow_ksp_max_it", "1"])
strip = [e.rsplit(" (log:", 1)[0] for e in (ce, pe)]
check(ps == cs == 3 and strip[0] == strip[1] and "coupling iteration" in pe,
      f"a diverged linear solve: exit 3 and the same line naming step, iteration and system: {pe!r}")
