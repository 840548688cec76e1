"""A catalogue of bad inputs (issue 12): each gets one line naming the key,
option or file and exit status 2, never an abort, a PETSc trace or a silent
NaN, and leaves no output directory behind; three of them also under
mpirun -n 2 (one rank's error ends both). A failure found while solving
gets exit 3, one line naming the step, and a summary that says failed. The
output directory and checkpoint cases run on both tracks."""
import fcntl
import json
import os
import subprocess
import tempfile

from support import (BINARY, EVERY_RANK, MPI_ENV, ROOT, check, crack_scenes, fault_group_scenes, flow_crack_scene,
                     foundation_fault_scene, mpirun, scene)

DEFAULT = scene("default")
with open(DEFAULT) as f:
    TEXT = f.read()


def without(key):
    """The default scene with the line that sets `key` removed."""
    path = os.path.join(tempfile.mkdtemp(), "scene.toml")
    with open(path, "w") as f:
        f.write("\n".join(l for l in TEXT.splitlines() if not l.startswith(key + " ")))
    return path


def written(text):
    path = os.path.join(tempfile.mkdtemp(), "scene.toml")
    with open(path, "w") as f:
        f.write(text)
    return path


BLOCK = scene("block3d")
HERTZ = scene("hertz")          # gmsh, no flow: faults without a pore pressure
FRACTURE = scene("fracture")    # gmsh, coupled
ELASTIC = scene("elastic_contact")  # a rectangle, no flow: a given pore pressure
CORRUPT_MSH = written("$MeshFormat\n4.1 0 8\nnot a mesh\n")
CORRUPT_MSH = CORRUPT_MSH.replace(".toml", ".msh")
with open(CORRUPT_MSH, "w") as f:
    f.write("$MeshFormat\n4.1 0 8\nnot a mesh\n")
CORRUPT_GEO = CORRUPT_MSH.replace(".msh", ".geo")
with open(CORRUPT_GEO, "w") as f:
    f.write("Point(1) = {0, 0, 0\n")
EMPTY = written("")
CRACK_GEO, CRACK, DEGENERATE = crack_scenes()  # CRACK: the .geo meshed once
LOOSE, SHARED, PINNED = fault_group_scenes()
FLOW_CRACK = flow_crack_scene()
REACTIVATION = scene("fault_reactivation")
REACTIVATION_CONDUIT = ("fault.fault.flow=conduit", "fault.fault.residual_aperture=1e-4",
                        "fault.fault.pore_pressure_load=false")
CONDUIT = "fault.crack.flow=conduit"
BOTH = ("check", "run")
# An error in the scene's text (READ) is found by the reader that check and
# run share before either acts (read_scene in cpp/main.cpp's execute, as
# the prototype's main): `check` shows it for both, and a few of them
# (BOTH) are run too. BOTH marks the errors found later, on the mesh or
# while setting up, where the two commands take their own paths.
READ = ("check",)
RUN = ("run",)


def s(*overrides):
    """--set arguments."""
    return [a for o in overrides for a in ("--set", o)]


# (label, scene file, arguments, what the message must name, commands). A
# PETSc option or --out only matters to `run`.
CASES = [
    # missing, unknown and malformed input
    ("missing key", without("mu_f"), [], "flow.mu_f", BOTH),
    ("missing table", written(TEXT.replace("[time]", "[tiem]")), [], "time", READ),
    ("unknown key", DEFAULT, s("mechanics.Ee=1.0"), "mechanics.Ee", BOTH),
    ("unknown key in a boundary", DEFAULT, s("boundary.top.tracton=[0.0, 1.0]"), "boundary.top.tracton", READ),
    ("unknown table", DEFAULT, s("nosuch.key=1"), "nosuch", READ),
    ("misspelt key of a required one", DEFAULT, s("time.adaptive={ tol = 1e-3 }"),
     "time.adaptive.tolerance: missing (a number is required; the table has tol: misspelt?)", READ),
    ("clamp and contact on one boundary", DEFAULT, s("boundary.bottom.clamp=true"), "boundary.bottom.clamp", READ),
    ("gmsh refinement out of range", BLOCK, s("mesh.refine=9"), "mesh.refine", READ),
    ("a zero mesh size factor", BLOCK, s("mesh.size_factor=0.0"), "mesh.size_factor: must be a finite number > 0",
     READ),
    ("a mesh size factor on a built-in mesh", DEFAULT, s("mesh.size_factor=0.5"), "mesh.size_factor", READ),
    ("--set without =", DEFAULT, s("mechanics"), "--set mechanics", READ),
    ("missing scene file", "no/such/scene.toml", [], "no/such/scene.toml", READ),
    ("scene file is a directory", os.path.dirname(DEFAULT), [], os.path.dirname(DEFAULT), READ),
    ("empty scene file", EMPTY, [], "mesh", READ),
    ("invalid TOML", written("[mesh\ntype = 1\n"), [], "invalid TOML", BOTH),
    ("unknown --option", DEFAULT, ["--foo"], "--foo", READ),
    ("unexpected argument", DEFAULT, ["extra_argument"], "extra_argument", READ),
    ("mistyped number", DEFAULT, s("mechanics.E='abc'"), "mechanics.E", BOTH),
    ("mistyped boolean", DEFAULT, s("output.xdmf=3"), "output.xdmf", READ),
    ("negative checkpoint interval", DEFAULT, s("output.checkpoint_every=-1"), "output.checkpoint_every", READ),
    ("zero progress interval", DEFAULT, s("output.progress_interval=0"), "output.progress_interval", READ),
    ("infinite progress interval", DEFAULT, s("output.progress_interval=inf"), "output.progress_interval", READ),
    ("mistyped string", DEFAULT, s("scene.name=[1, 2]"), "scene.name", READ),
    ("unknown scheme", DEFAULT, s("coupling.scheme=undrained"), "coupling.scheme", READ),
    ("unknown L", DEFAULT, s("coupling.L=optimal"), "coupling.L", READ),
    ("unknown mesh type", DEFAULT, s("mesh.type=sphere"), "mesh.type", READ),
    ("unknown boundary name", DEFAULT, s("boundary.middle.pressure=0.0"), "boundary.middle", READ),
    # out of range
    ("negative E", DEFAULT, s("mechanics.E=-1.0"), "mechanics.E", BOTH),
    ("zero E", DEFAULT, s("mechanics.E=0"), "mechanics.E", READ),
    ("nu = 0.5", DEFAULT, s("mechanics.nu=0.5"), "mechanics.nu", READ),
    ("nu > 0.5", DEFAULT, s("mechanics.nu=0.7"), "mechanics.nu", READ),
    ("nu < -1", DEFAULT, s("mechanics.nu=-1.5"), "mechanics.nu", READ),
    ("negative permeability", DEFAULT, s("flow.permeability=-1e-13"), "flow.permeability", READ),
    ("zero viscosity", DEFAULT, s("flow.mu_f=0"), "flow.mu_f", READ),
    ("porosity above 1", DEFAULT, s("flow.phi0=1.5"), "flow.phi0", READ),
    ("negative compressibility", DEFAULT, s("flow.c_f=-1"), "flow.c_f", READ),
    ("zero Biot modulus", DEFAULT, s("flow.M=0.0"), "flow.M", READ),
    ("alpha > 1", DEFAULT, s("coupling.alpha=1.5"), "coupling.alpha", READ),
    ("alpha < 0", DEFAULT, s("coupling.alpha=-0.5"), "coupling.alpha", READ),
    ("q = 0", DEFAULT, s("coupling.q=0"), "coupling.q", READ),
    ("q a word other than auto", DEFAULT, s("coupling.scheme=multirate", "coupling.q='fast'"), "coupling.q", READ),
    ("q = auto with single rate", DEFAULT, s("coupling.q=auto"), "coupling.q", READ),
    ("q_max without q = auto", DEFAULT, s("coupling.scheme=multirate", "coupling.q=2", "coupling.q_max=8"),
     "coupling.q_max", READ),
    ("q_tolerance without q = auto", DEFAULT, s("coupling.scheme=multirate", "coupling.q_tolerance=1e-3"),
     "coupling.q_tolerance", READ),
    ("q_max = 0", DEFAULT, s("coupling.scheme=multirate", "coupling.q=auto", "coupling.q_max=0"), "coupling.q_max",
     READ),
    ("q_max not an integer", DEFAULT, s("coupling.scheme=multirate", "coupling.q=auto", "coupling.q_max=2.5"),
     "coupling.q_max", READ),
    ("q_tolerance >= 1", DEFAULT, s("coupling.scheme=multirate", "coupling.q=auto", "coupling.q_tolerance=1.0"),
     "coupling.q_tolerance", READ),
    ("q_tolerance not a number", DEFAULT,
     s("coupling.scheme=multirate", "coupling.q=auto", "coupling.q_tolerance='small'"), "coupling.q_tolerance", READ),
    ("negative tolerance", DEFAULT, s("coupling.tolerance=-1"), "coupling.tolerance", READ),
    ("zero iterations", DEFAULT, s("coupling.max_iterations=0"), "coupling.max_iterations", READ),
    ("unknown acceleration", DEFAULT, s("coupling.acceleration=aitken"), "coupling.acceleration", READ),
    ("Anderson depth 0", DEFAULT, s("coupling.acceleration=anderson", "coupling.depth=0"), "coupling.depth", READ),
    ("accelerated monolithic", DEFAULT, s("coupling.scheme=monolithic", "coupling.acceleration=anderson"),
     "coupling.acceleration", READ),
    ("unknown fallback", DEFAULT, s("coupling.fallback=newton"), "coupling.fallback", READ),
    ("mistyped pin_cycles", DEFAULT, s("coupling.pin_cycles=1"), "coupling.pin_cycles", READ),
    ("a fallback for the monolithic scheme", DEFAULT, s("coupling.scheme=monolithic", "coupling.fallback=monolithic"),
     "coupling.fallback", READ),
    ("two-pass multirate without storage", DEFAULT,
     s("coupling.scheme=multirate-two-pass", "coupling.q=4", "flow.M=inf", "flow.c_f=0.0"), "coupling.scheme", READ),
    ("negative L", DEFAULT, s("coupling.L=-1"), "coupling.L", READ),
    ("dt = 0", DEFAULT, s("time.dt=0.0"), "time.dt", READ),
    ("dt < 0", DEFAULT, s("time.dt=-0.1"), "time.dt", READ),
    ("negative end", DEFAULT, s("time.end=-1"), "time.end", READ),
    ("growth < 1", DEFAULT, s("time.growth=0.5"), "time.growth", READ),
    ("unknown time scheme", DEFAULT, s("time.scheme=crank-nicolson"), "time.scheme", READ),
    ("time scheme not a string", DEFAULT, s("time.scheme=2"), "time.scheme", READ),
    ("adaptive tolerance missing", DEFAULT, s("time.adaptive.dt_min=0.01"), "time.adaptive.tolerance", READ),
    ("adaptive tolerance >= 1", DEFAULT, s("time.adaptive.tolerance=1.5"), "time.adaptive.tolerance", READ),
    ("adaptive tolerance not a number", DEFAULT, s("time.adaptive.tolerance='tight'"), "time.adaptive.tolerance",
     READ),
    ("adaptive dt_min above dt", DEFAULT, s("time.adaptive.tolerance=1e-3", "time.adaptive.dt_min=1.0"),
     "time.adaptive.dt_min", READ),
    ("adaptive dt_max below dt", DEFAULT, s("time.adaptive.tolerance=1e-3", "time.adaptive.dt_max=0.01"),
     "time.adaptive.dt_max", READ),
    ("adaptive dt_min too small", DEFAULT, s("time.adaptive.tolerance=1e-3", "time.adaptive.dt_min=1e-9"),
     "time.adaptive.dt_min", READ),
    ("unknown adaptive key", DEFAULT, s("time.adaptive.tolerance=1e-3", "time.adaptive.safety=0.9"),
     "time.adaptive.safety", READ),
    ("adaptive not a table", DEFAULT, s("time.adaptive=1e-3"), "time.adaptive", READ),
    ("output times not an array", DEFAULT, s("output.times=1.0"), "output.times", READ),
    ("output times decreasing", DEFAULT, s("output.times=[2.0, 1.0]"), "output.times", READ),
    ("output time after the end", DEFAULT, s("output.times=[1.0, 20.0]"), "output.times", READ),
    ("output time not a step's end", DEFAULT, s("output.times=[1.1]"), "output.times", READ),
    ("output time inside a window", DEFAULT, s("coupling.scheme=multirate", "coupling.q=4", "output.times=[0.4]"),
     "output.times", READ),
    ("output every <= 0", DEFAULT, s("output.every=0.0"), "output.every", READ),
    ("output every not a step multiple", DEFAULT, s("output.every=0.3"), "output.every", READ),
    ("output times and every", DEFAULT, s("output.times=[1.0]", "output.every=1.0"), "output.every", READ),
    ("zero cells", DEFAULT, s("mesh.cells=[0, 4]"), "mesh.cells", READ),
    ("fractional cells", DEFAULT, s("mesh.cells=[10.5, 4]"), "mesh.cells", READ),
    ("cells of the wrong length", DEFAULT, s("mesh.cells=[10]"), "mesh.cells", READ),
    ("upper below lower", DEFAULT, s("mesh.upper=[-1, 1]"), "mesh.upper", READ),
    ("zero foundation normal", DEFAULT, s("boundary.bottom.contact.normal=[0, 0]"), "boundary.bottom.contact.normal",
     READ),
    ("normal of the wrong dimension", DEFAULT, s("boundary.bottom.contact.normal=[0, -1, 0]"),
     "boundary.bottom.contact.normal", READ),
    ("normal that depends on t", DEFAULT, s("boundary.bottom.contact.normal=['0', '-1-t']"),
     "boundary.bottom.contact.normal", READ),
    ("normal zero at a contact node", DEFAULT, s("boundary.bottom.contact.normal=['0', '-x']"),
     "boundary.bottom.contact.normal", RUN),
    ("normal NaN at a contact node", DEFAULT, s("boundary.bottom.contact.normal=['0', '-sqrt(x-5)']"),
     "boundary.bottom.contact.normal", RUN),
    ("opposite normals meet at a node", DEFAULT,
     s("boundary.right.contact={ gap = 0.1, normal = [0.0, 1.0] }"), "contact.normal", RUN),
    ("inclined normal at a node with a prescribed component", scene("hertz"),
     s("boundary.arc.contact.normal=[0.6, -0.8]"), "boundary.arc.contact.normal", RUN),
    ("negative gap", DEFAULT, s("boundary.bottom.contact.gap=-0.1"), "boundary.bottom.contact.gap", READ),
    ("negative gap where evaluated", DEFAULT, s("boundary.bottom.contact.gap='x-5'"), "boundary.bottom.contact.gap",
     RUN),
    ("gravity of the wrong length", DEFAULT, s("flow.gravity=[0, 0, -9.8]", "flow.rho_f=1000"), "flow.gravity",
     READ),
    ("permeability tensor of the wrong shape", DEFAULT, s("flow.permeability=[[1e-13, 0], [0, 1e-13], [0, 0]]"),
     "flow.permeability", READ),
    # inconsistent
    ("end not a multiple of dt", DEFAULT, s("time.dt=0.7"), "time.dt", READ),
    ("q does not divide the steps", DEFAULT, s("coupling.scheme=multirate", "coupling.q=7"), "coupling.q", READ),
    ("growth with multirate", DEFAULT, s("time.growth=1.1", "coupling.scheme=multirate", "coupling.q=2"),
     "time.growth", READ),
    ("adaptive with growth", DEFAULT, s("time.growth=1.1", "time.adaptive.tolerance=1e-3"), "time.adaptive", READ),
    ("adaptive with multirate", DEFAULT, s("time.adaptive.tolerance=1e-3", "coupling.scheme=multirate",
                                           "coupling.q=2"), "time.adaptive", READ),
    ("adaptive with q = auto", DEFAULT, s("time.adaptive.tolerance=1e-3", "coupling.scheme=multirate",
                                          "coupling.q=auto"), "time.adaptive", READ),
    ("growth with q = auto", DEFAULT, s("time.growth=1.1", "coupling.scheme=multirate", "coupling.q=auto"),
     "time.growth", READ),
    ("rho_f without gravity", DEFAULT, s("flow.rho_f=1000"), "flow.gravity", READ),
    ("E with G", DEFAULT, s("mechanics.G=1e9"), "mechanics.E", READ),
    ("two mechanics conditions", DEFAULT, s("boundary.left.traction=[0, 1]"), "boundary.left", READ),
    ("pressure and flux", DEFAULT, s("boundary.top.flux=1.0"), "boundary.top.flux", READ),
    ("flux and rate", DEFAULT, s("boundary.bottom.flux=0.0", "boundary.bottom.rate=1.0"), "boundary.bottom.rate",
     READ),
    ("a rate that varies along the boundary", DEFAULT, s("boundary.bottom.rate='1e-6*x'"), "boundary.bottom.rate",
     READ),
    ("NaN flux", DEFAULT, s("boundary.bottom.flux='sqrt(-1-x)'"), "boundary.bottom.flux", BOTH),
    ("a flux on a curved boundary", scene("hertz_poroelastic"), s("boundary.arc.flux=-1e-6"), "boundary.arc.flux",
     BOTH),
    ("a well outside the mesh", DEFAULT, s("well.w.position=[100.0, 0.5]", "well.w.rate=1.0"), "well.w.position",
     BOTH),
    ("a well rate that varies in space", DEFAULT, s("well.w.position=[5.0, 0.5]", "well.w.rate='x'"),
     "well.w.rate", READ),
    ("a well without a rate", DEFAULT, s("well.w.position=[5.0, 0.5]"), "well.w.rate", READ),
    # material regions
    ("a region without where on a built-in mesh", DEFAULT, s("region.r.E=2e9"), "region.r.where", READ),
    ("a region that is no group of the gmsh file", scene("hertz"), s("region.rock.E=2e9"), "region.rock", BOTH),
    ("two regions that claim one cell", DEFAULT, s("region.a.where='x < 6'", "region.b.where='x > 4'"),
     "region.b", BOTH),
    ("a region that holds no cell", DEFAULT, s("region.r.where='x > 100'"), "region.r", BOTH),
    ("a region key the physics do not have", scene("hertz"), s("region.r.where='x > 0'", "region.r.M=1e10"),
     "region.r.M", READ),
    ("an unknown region key", DEFAULT, s("region.r.where='x > 5'", "region.r.mu_f=1e-3"), "region.r.mu_f", READ),
    ("a region nu of 0.5", DEFAULT, s("region.r.where='x > 5'", "region.r.nu=0.5"), "region.r.nu", READ),
    ("a region permeability below zero", DEFAULT, s("region.r.where='x > 5'", "region.r.permeability=-1e-13"),
     "region.r.permeability", READ),
    ("a region permeability zero where evaluated", DEFAULT,
     s("region.r.where='x > 5'", "region.r.permeability='1e-13*(x-7)'"), "region.r.permeability", BOTH),
    ("a pore pressure load without contact", DEFAULT, s("boundary.top.pore_pressure_load=true"),
     "boundary.top.pore_pressure_load", READ),
    ("a pore pressure load in a scene without flow", scene("elastic_contact"),
     s("boundary.bottom.pore_pressure_load=true"), "boundary.bottom.pore_pressure_load", READ),
    ("a pore pressure load that is no boolean", DEFAULT, s("boundary.bottom.pore_pressure_load=1"),
     "boundary.bottom.pore_pressure_load", READ),
    # faults (issue 37)
    ("a fault on a built-in mesh", DEFAULT, s("fault.f.gap=0.0"), "fault.f", READ),
    ("a fault that is also a boundary", HERTZ, s("fault.top.gap=0.0"), "fault.top", READ),
    ("a fault gap that depends on t", HERTZ, s("fault.f.gap='1e-3*t'"), "fault.f.gap", READ),
    ("a fault with pressure and pore_pressure_load", FRACTURE,
     s("fault.f.pressure=1e5", "fault.f.pore_pressure_load=true"), "fault.f.pore_pressure_load", READ),
    ("a fault pore pressure load without a pore pressure", HERTZ, s("fault.f.pore_pressure_load=true"),
     "fault.f.pore_pressure_load", READ),
    ("an unknown fault flow", HERTZ, s("fault.f.flow=leaky"), "fault.f.flow", READ),
    ("a sealing fault without flow", HERTZ, s("fault.f.flow=sealing"), "fault.f.flow", READ),
    ("a fault held at no pressure", FRACTURE, s("fault.f.flow=pressure"), "fault.f.pressure", READ),
    ("a zero fault normal", HERTZ, s("fault.f.normal=[0, 0]"), "fault.f.normal", READ),
    ("an infinite fault normal", HERTZ, s("fault.f.normal=[inf, 1]"), "fault.f.normal", READ),
    ("a fault normal of the wrong length", HERTZ, s("fault.f.normal=[0, 0, 1]"), "fault.f.normal", READ),
    ("an unknown fault key", HERTZ, s("fault.f.aperture=1e-3"), "fault.f.aperture", READ),
    ("a fault that is no table", HERTZ, s("fault.f=1"), "fault.f", READ),
    ("a fault group that does not exist", CRACK, s("fault.nowhere.gap=0.0"), "fault.nowhere", BOTH),
    ("a fault group of the wrong dimension", CRACK, s("fault.rock.gap=0.0"), "fault.rock", BOTH),
    ("a fault group on the outer boundary", CRACK, s("fault.top.gap=0.0"), "fault.top", BOTH),
    ("faults that meet where a displacement is prescribed", PINNED, [], "is not perpendicular to the faults", BOTH),
    # issue 51: the real cause named
    ("a fault curve not embedded in the surface", LOOSE, [], "Curve{..} In Surface{..}", BOTH),
    ("one curve in two faults' groups", SHARED, [], "the physical groups crack and other share", BOTH),
    ("a fault array of the mesh's other dimension", CRACK, s("fault.crack.normal=[0.0, 1.0, 0.0]"),
     "one per axis (mesh.dimension = 2)", READ),
    ("names that refer to one another", DEFAULT, s("expressions.a='b'", "expressions.b='2*a'"), "expressions.a",
     READ),
    ("a name that is a function", DEFAULT, s("expressions.sqrt=2.0"), "expressions.sqrt", READ),
    ("a name that is no identifier", DEFAULT, s("expressions.'2a'=2.0"), "expressions.'2a'", READ),
    ("a named expression that does not parse", DEFAULT, s("expressions.a='1 +'"), "expressions.a", READ),
    ("a named expression that is NaN where used", DEFAULT,
     s("expressions.a='sqrt(x - 20)'", "boundary.top.traction=[0.0, 'a']"), "boundary.top.traction", BOTH),
    ("E an expression of x", DEFAULT, s("mechanics.E='1e9*(1 + x)'"), "mechanics.E", READ),
    ("E an expression that is NaN", DEFAULT, s("mechanics.E='sqrt(-1)'"), "mechanics.E: \"sqrt(-1)\" gives NaN", READ),
    ("a negative fault gap", CRACK, s("fault.crack.gap=-1e-3"), "fault.crack.gap", BOTH),
    # Tips graded by the project (issue 53, item 3)
    ("a negative tip size", CRACK_GEO, s("fault.crack.tip_size=-0.01"), "fault.crack.tip_size", READ),
    ("a tip grading without a tip size", CRACK_GEO, s("fault.crack.tip_grading=0.3"), "fault.crack.tip_grading", READ),
    ("a zero tip grading", CRACK_GEO, s("fault.crack.tip_size=0.01", "fault.crack.tip_grading=0.0"),
     "fault.crack.tip_grading", READ),
    ("a tip size on a .msh mesh", CRACK_GEO, s(f"mesh.file={CORRUPT_MSH}", "fault.crack.tip_size=0.01"),
     "fault.crack.tip_size: needs a .geo", READ),
    ("a mesh size factor on a .msh mesh", CRACK, s(f"mesh.file={CORRUPT_MSH}", "mesh.size_factor=0.5"),
     "mesh.size_factor: needs a .geo", READ),
    ("a tip size on a .geo with size fields of its own", CRACK_GEO, s("fault.crack.tip_size=0.01"),
     "fault.crack.tip_size: ", BOTH),
    # issue 50: the condensed path failed with PETSc error 81, the full one
    # counted the foundation's force wrong at the fault's end
    ("a fault that reaches a contact boundary", foundation_fault_scene(), [], "fault.fault", BOTH),
    ("a fault pressure that is NaN", CRACK, s("fault.crack.pressure='sqrt(x - 10)'"), "fault.crack.pressure", BOTH),
    ("a degenerate cell", DEGENERATE, [], "degenerate.geo", BOTH),
    ("a negative friction", HERTZ, s("fault.f.friction=-0.1"), "fault.f.friction", READ),
    ("a friction that is NaN", HERTZ, s("fault.f.friction=nan"), "fault.f.friction", READ),
    ("a negative cohesion", HERTZ, s("fault.f.cohesion=-1.0"), "fault.f.cohesion", READ),
    ("a Tresca bound with friction", HERTZ, s("fault.f.tresca=1e6", "fault.f.friction=0.3"), "fault.f.tresca",
     READ),
    ("a negative Tresca bound", HERTZ, s("fault.f.tresca=-1.0"), "fault.f.tresca", READ),
    ("a negative contact friction", HERTZ, s("boundary.arc.contact.friction=-0.3"), "boundary.arc.contact.friction",
     READ),
    ("friction on a boundary without contact", HERTZ, s("boundary.top.friction=0.3"), "boundary.top.friction", READ),
    ("friction where two foundations meet", scene("groove"), s("boundary.left_flank.contact.friction=0.3"),
     "boundary.left_flank.contact.friction", RUN),
    # Conduit faults (issue 39)
    ("a conduit fault without a residual aperture", FLOW_CRACK, s(CONDUIT), "fault.crack.residual_aperture", READ),
    ("a zero residual aperture", FLOW_CRACK, s(CONDUIT, "fault.crack.residual_aperture=0.0"),
     "fault.crack.residual_aperture", READ),
    ("a residual aperture that is NaN", FLOW_CRACK, s(CONDUIT, "fault.crack.residual_aperture=nan"),
     "fault.crack.residual_aperture", READ),
    ("a negative normal permeability", FLOW_CRACK,
     s(CONDUIT, "fault.crack.residual_aperture=1e-4", "fault.crack.normal_permeability=-1.0"),
     "fault.crack.normal_permeability", READ),
    ("a normal permeability neither a number nor inf", FLOW_CRACK,
     s(CONDUIT, "fault.crack.residual_aperture=1e-4", "fault.crack.normal_permeability=infinite"),
     "fault.crack.normal_permeability", READ),
    ("a residual aperture on a fault that is no conduit", FLOW_CRACK, s("fault.crack.residual_aperture=1e-4"),
     "fault.crack.residual_aperture", READ),
    ("a fault permeability on a fault that is no conduit", FLOW_CRACK, s("fault.crack.permeability=1e-10"),
     "fault.crack.permeability: only a conduit fault", READ),
    ("a negative fault permeability", FLOW_CRACK,
     s(CONDUIT, "fault.crack.residual_aperture=1e-4", "fault.crack.permeability=-1e-10"),
     "fault.crack.permeability", READ),
    ("a conduit fault with a pressure", FLOW_CRACK, s(CONDUIT, "fault.crack.residual_aperture=1e-4",
                                                       "fault.crack.pressure=1e6"), "fault.crack.pressure", READ),
    ("a conduit fault loaded by the pore pressure", FLOW_CRACK,
     s(CONDUIT, "fault.crack.residual_aperture=1e-4", "fault.crack.pore_pressure_load=true"),
     "fault.crack.pore_pressure_load", READ),
    ("a conduit fault without [flow]", CRACK, s(CONDUIT, "fault.crack.residual_aperture=1e-4"), "fault.crack.flow",
     READ),
    ("a well on a fault that does not exist", FLOW_CRACK,
     s(CONDUIT, "fault.crack.residual_aperture=1e-4", "well.inj.position=[0.0, 0.0]", "well.inj.rate=1e-6",
       "well.inj.fault=nowhere"), "well.inj.fault", READ),
    ("a well on a fault that is no conduit", FLOW_CRACK,
     s("well.inj.position=[0.0, 0.0]", "well.inj.rate=1e-6", "well.inj.fault=crack"), "well.inj.fault", READ),
    ("a well off its fault", FLOW_CRACK,
     s(CONDUIT, "fault.crack.residual_aperture=1e-4", "well.inj.position=[0.0, 5.0]", "well.inj.rate=1e-6",
       "well.inj.fault=crack"), "well.inj.position", BOTH),
    ("a conduit fault with BDF2 and a multirate scheme", REACTIVATION,
     s(*REACTIVATION_CONDUIT, 'time.scheme="bdf2"', 'coupling.scheme="multirate"'), "fault.fault.flow", READ),
    ("a closure in a scene without mechanics", FLOW_CRACK,
     s(CONDUIT, "fault.crack.residual_aperture=1e-4", "fault.crack.closure={ V_m = 1e-4, K_ni = 1e10 }"),
     "fault.crack.closure", READ),
    ("a closure that is not a table", REACTIVATION, s(*REACTIVATION_CONDUIT, "fault.fault.closure=1e-4"),
     "fault.fault.closure", READ),
    ("a zero largest closure", REACTIVATION,
     s(*REACTIVATION_CONDUIT, "fault.fault.closure={ V_m = 0.0, K_ni = 1e10 }"), "fault.fault.closure.V_m", READ),
    ("a closure stiffness that is NaN", REACTIVATION,
     s(*REACTIVATION_CONDUIT, "fault.fault.closure={ V_m = 1e-4, K_ni = nan }"), "fault.fault.closure.K_ni", READ),
    ("a negative closure stiffness", REACTIVATION,
     s(*REACTIVATION_CONDUIT, "fault.fault.closure={ V_m = 1e-4, K_ni = -1e10 }"), "fault.fault.closure.K_ni",
     READ),
    ("a closure without its stiffness", REACTIVATION, s(*REACTIVATION_CONDUIT, "fault.fault.closure={ V_m = 1e-4 }"),
     "fault.fault.closure.K_ni", READ),
    ("a closure with an unknown key", REACTIVATION,
     s(*REACTIVATION_CONDUIT, "fault.fault.closure={ V_m = 1e-4, K_ni = 1e10, K = 1.0 }"), "fault.fault.closure.K",
     READ),
    ("a closure on a fault that is no conduit", REACTIVATION, s("fault.fault.closure={ V_m = 1e-4, K_ni = 1e10 }"),
     "fault.fault.closure", READ),
    ("a foundation normal into the body", DEFAULT, s("boundary.bottom.contact.normal=[0.0, 1.0]"),
     "boundary.bottom.contact.normal", BOTH),
    # a given pore pressure (one-way coupling)
    ("a given pore pressure with flow", DEFAULT, s("mechanics.pore_pressure=1e5", "mechanics.alpha=1.0"),
     "mechanics.pore_pressure", READ),
    ("a given pore pressure without alpha", ELASTIC, s("mechanics.pore_pressure=1e5"), "mechanics.alpha", READ),
    ("mechanics.alpha without a given pore pressure", ELASTIC, s("mechanics.alpha=0.8"), "mechanics.alpha", READ),
    ("mechanics.alpha = 0", ELASTIC, s("mechanics.pore_pressure=1e5", "mechanics.alpha=0.0"), "mechanics.alpha",
     READ),
    ("mechanics.alpha > 1", ELASTIC, s("mechanics.pore_pressure=1e5", "mechanics.alpha=1.5"), "mechanics.alpha",
     READ),
    ("a NaN given pore pressure", ELASTIC, s("mechanics.pore_pressure='sqrt(-1-x)'", "mechanics.alpha=1.0"),
     "mechanics.pore_pressure", BOTH),
    ("an infinite given pore pressure at the end", ELASTIC,
     s("mechanics.pore_pressure='1e5/(t-1)'", "mechanics.alpha=1.0"), "mechanics.pore_pressure", BOTH),
    ("a closed form with regions", scene("terzaghi"), s("region.r.where='y > 5'", "region.r.G=2e9"),
     "reference.solution", READ),
    # too large
    ("1e20 steps", DEFAULT, s("time.end=1e20", "time.dt=1"), "time.dt", READ),
    ("3e9 steps", DEFAULT, s("time.end=3e9", "time.dt=1"), "time.dt", READ),
    ("steps that barely grow", DEFAULT, s("time.growth=1.0000001", "time.dt=1e-9", "time.end=1e9"), "time.growth",
     READ),
    ("a mesh larger than the machine", DEFAULT, s("mesh.cells=[4000000, 4000000]"), "mesh.cells", READ),
    # expressions
    ("bad expression", DEFAULT, s("boundary.top.pressure='x +* 2'"), "boundary.top.pressure", BOTH),
    ("NaN traction", DEFAULT, s("boundary.top.traction=['0', 'sqrt(-1)']"), "boundary.top.traction", BOTH),
    ("infinite traction", DEFAULT, s("boundary.top.traction=['0', '-1e3/(t-t)']"), "boundary.top.traction", BOTH),
    ("NaN initial pressure", DEFAULT, s("flow.initial_pressure='log(x-100)'"), "flow.initial_pressure", BOTH),
    ("infinite source", DEFAULT, s("flow.source='1/(x-x)'"), "flow.source", BOTH),
    ("NaN boundary pressure", DEFAULT, s("boundary.top.pressure='0/0'"), "boundary.top.pressure", BOTH),
    ("NaN body force", DEFAULT, s("mechanics.body_force=['0', 'sqrt(-1)']"), "mechanics.body_force", BOTH),
    ("NaN gap", DEFAULT, s("boundary.bottom.contact.gap='sqrt(-1)'"), "boundary.bottom.contact.gap: is NaN at", RUN),
    # mesh files
    ("missing mesh file", DEFAULT, s("mesh.type=gmsh", "mesh.file=nope.msh"), "nope.msh", READ),
    ("corrupt .msh", BLOCK, s(f"mesh.file={CORRUPT_MSH}"), CORRUPT_MSH, BOTH),
    ("corrupt .geo", BLOCK, s(f"mesh.file={CORRUPT_GEO}"), CORRUPT_GEO, BOTH),
    # solver options and the output directory
    ("PETSc options that make no solver", DEFAULT, ["-flow_pc_type", "nonexistent"], "flow", RUN),
    ("no bounds in the contact solver", DEFAULT, ["-mechanics_snes_type", "newtonls"], "-mechanics_snes_type", RUN),
    ("no bounds in the condensed contact solver", DEFAULT, ["-mechanics_contact_snes_type", "newtonls"],
     "-mechanics_contact_snes_type", RUN),
    # its preconditioner needs the reduced space's inactive set (a segfault
    # in C++, a wrong size in the prototype before 2026-12-05)
    ("no inactive set for the iterative contact solver", DEFAULT,
     s("solver.mechanics=iterative") + ["-mechanics_snes_type", "vinewtonssls"], "-mechanics_snes_type vinewtonssls",
     RUN),
    # preonly with no factorisation: a wrong flow passed as solved (exit 0)
    # before 2026-12-05
    ("preonly without a factorisation", DEFAULT, ["-flow_ksp_type", "preonly", "-flow_pc_type", "none"],
     "-flow_ksp_type preonly", RUN),
    ("a relative tolerance of 1 or more", DEFAULT, ["-mechanics_snes_rtol", "2"], "-mechanics_snes_rtol 2", RUN),
    ("a line search the contact solver cannot take", DEFAULT, ["-mechanics_contact_snes_linesearch_type", "nleqerr"],
     "-mechanics_contact_snes_linesearch_type nleqerr", RUN),
    ("preonly with redundant around no factorisation", DEFAULT,
     ["-mechanics_ksp_type", "preonly", "-mechanics_pc_type", "redundant", "-mechanics_redundant_pc_type", "jacobi"],
     "-mechanics_redundant_pc_type jacobi", RUN),
    ("an output directory that cannot be made", DEFAULT, ["--out", "/proc/x"], "/proc/x", RUN),
    ("negative time.retry", DEFAULT, s("time.retry=-1"), "time.retry", READ),
    ("time.retry too large", DEFAULT, s("time.retry=40"), "time.retry", READ),
    ("time.retry not an integer", DEFAULT, s("time.retry=1.5"), "time.retry", READ),
    # [solver]
    ("unknown solver choice", DEFAULT, s("solver.flow=gpu"), "solver.flow", READ),
    ("solver choice not a string", DEFAULT, s("solver.mechanics=1"), "solver.mechanics", READ),
    ("unknown key in [solver]", DEFAULT, s("solver.mechanic=direct"), "solver.mechanic", READ),
    ("negative cells per rank", DEFAULT, s("solver.cells_per_rank=-1"), "solver.cells_per_rank: must be >= 0", READ),
    ("cells per rank not an integer", DEFAULT, s("solver.cells_per_rank=1e4"), "solver.cells_per_rank", READ),
    ("a field split without fields", DEFAULT, ["-mechanics_pc_type", "fieldsplit"], "-mechanics_pc_type", RUN),
    ("contact_condensed not a boolean", DEFAULT, ["-mechanics_contact_condensed", "maybe"],
     "-mechanics_contact_condensed", RUN),
]
# Under mpirun -n 2 (an error found by one rank must end both).
MPI_CASES = ["negative gap where evaluated", "an output directory that cannot be made", "corrupt .msh"]

runs = 0
for label, path, arguments, key, commands in CASES:
    for command in commands:
        for ranks in ((1, 2) if label in MPI_CASES and command == "run" else (1,)):
            out = os.path.join(tempfile.mkdtemp(), "out")
            args = [BINARY, command, path] + arguments
            if command == "run" and "--out" not in arguments:
                args += ["--out", out]
            if ranks > 1:
                args = mpirun(ranks) + args + EVERY_RANK
            p = subprocess.run(args, capture_output=True, text=True, timeout=120, env=MPI_ENV)
            ours = [line for line in p.stderr.strip().splitlines() if line.startswith("biotcontact")]
            where = f"{label} ({command}{', 2 ranks' if ranks > 1 else ''})"
            check(p.returncode == 2, f"{where}: exit status {p.returncode} == 2 ({p.stderr.strip()[-300:]!r})")
            check(len(ours) == 1 and ours[0].startswith("biotcontact: error:") and key in ours[0]
                  and (ranks > 1 or len(p.stderr.strip().splitlines()) == 1),
                  f"{where}: one line naming {key!r}: {p.stderr.strip()!r}")
            check("PETSC ERROR" not in p.stdout + p.stderr and "terminate called" not in p.stderr
                  and "Signal:" not in p.stderr, f"{where}: no PETSc trace or abort")
            check(not os.path.exists(out), f"{where}: no output directory left behind")
            runs += 1
check(len(CASES) >= 60, f"{len(CASES)} bad inputs in the catalogue ({runs} runs, {len(MPI_CASES)} also on 2 ranks)")

# A failure found while solving: exit 3, one line naming the step, time and
# system, and everything before it written with status "failed".
out = tempfile.mkdtemp()
p = subprocess.run([BINARY, "run", DEFAULT, "--out", out, "-flow_ksp_type", "gmres", "-flow_pc_type", "none",
                    "-flow_ksp_max_it", "1"], capture_output=True, text=True, timeout=120)
lines = p.stderr.strip().splitlines()
check(p.returncode == 3 and len(lines) == 1 and "step 1 (t = 0.2): coupling iteration" in lines[0]
      and "flow" in lines[0]
      and "DIVERGED_ITS" in lines[0], f"a diverged linear solve: exit 3, one line: {p.stderr.strip()!r}")
with open(os.path.join(out, "summary.json")) as f:
    summary = json.load(f)
check(summary["status"] == "failed" and summary["steps"] == 0 and "DIVERGED_ITS" in summary["failure"],
      "a diverged linear solve: summary.json says failed, with the cause")

p = subprocess.run([BINARY, "check", DEFAULT], capture_output=True, text=True)
check(p.returncode == 0 and "ok" in p.stdout, "the shipped default scene passes check")
p = subprocess.run([BINARY, "frobnicate"], capture_output=True, text=True)
check(p.returncode == 2 and p.stderr.count("\n") == 1, "an unknown command is refused in one line")

# The output directory and checkpoints (issue 21), both tracks: a directory
# another run holds, a restart where there is no checkpoint, and a restart
# with other --set values than the checkpointed run. Each is one line naming
# the directory, exit 2, and touches no file there.
PROTOTYPE_RUN = ["/usr/bin/python3", "-m", "python_prototype", "run", DEFAULT]
SMALL = ["--set", "mesh.cells=[20,2]", "--set", "time.end=0.4", "--set", "output.checkpoint_every=1"]


def stamps(directory):
    """Each file's modification time (.lock records who holds the directory)."""
    return {name: os.stat(os.path.join(directory, name)).st_mtime_ns for name in os.listdir(directory)
            if name != ".lock"}


def directory_case(label, track, arguments, directory, key):
    before = stamps(directory)
    p = subprocess.run(track + arguments, capture_output=True, text=True, timeout=300, env=MPI_ENV, cwd=ROOT)
    after = stamps(directory)
    where = f"{label} ({'C++' if track[0] == BINARY else 'prototype'})"
    check(p.returncode == 2 and len(p.stderr.strip().splitlines()) == 1 and key in p.stderr
          and p.stderr.startswith("biotcontact: error:"), f"{where}: exit 2, one line naming {key!r}: "
          f"{p.stderr.strip()!r}")
    check(before == after, f"{where}: no file in {directory} touched")
    return p.stderr.strip()


messages = []
for track in ([BINARY, "run", DEFAULT], PROTOTYPE_RUN):
    held = tempfile.mkdtemp(prefix="held-")
    with open(os.path.join(held, ".lock"), "w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX | fcntl.LOCK_NB)
        lock.write("process 1 on this host, started 2026-11-24 12:00:00\n")
        lock.flush()
        message = directory_case("an output directory in use", track, ["--out", held, *SMALL], held,
                                 f"--out {held}: the directory is in use by another run (process 1")
        messages.append(message.replace(held, "DIR"))
    empty = tempfile.mkdtemp(prefix="no-checkpoint-")
    directory_case("a restart without a checkpoint", track, ["--restart", empty, *SMALL], empty,
                   f"--restart {empty}: no checkpoint there")
    checkpointed = tempfile.mkdtemp(prefix="checkpointed-")
    p = subprocess.run(track + ["--out", checkpointed, *SMALL], capture_output=True, text=True, timeout=300,
                       env=MPI_ENV, cwd=ROOT)
    check(p.returncode == 0, f"a run that leaves a checkpoint ({p.stderr.strip()[-200:]!r})")
    directory_case("a restart with other --set values", track,
                   ["--restart", checkpointed, *SMALL, "--set", "coupling.L=kdr"], checkpointed,
                   f"--restart {checkpointed}: the checkpoint was written for another scene or other --set values")
    # A restart may change how the coupling is solved (test_cohesive_opening),
    # not its time steps: a multirate scheme is another scene.
    directory_case("a restart with a multirate scheme", track,
                   ["--restart", checkpointed, *SMALL, "--set", 'coupling.scheme="multirate"'], checkpointed,
                   'a restart may change with --set coupling.scheme between "fixed-stress" and "monolithic"')
    # A frictionless run's checkpoint holds no stick/slip state to continue
    # from: a restart that adds friction to its fault is another scene.
    frictionless = tempfile.mkdtemp(prefix="frictionless-")
    CRACK_STEPS = ["--set", "time.end=2.0", "--set", "output.checkpoint_every=1"]
    p = subprocess.run(track[:-1] + [CRACK, "--out", frictionless, *CRACK_STEPS], capture_output=True, text=True,
                       timeout=300, env=MPI_ENV, cwd=ROOT)
    check(p.returncode == 0, f"a frictionless fault run that leaves a checkpoint ({p.stderr.strip()[-200:]!r})")
    directory_case("a restart adding friction to a frictionless checkpoint", track[:-1],
                   [CRACK, "--restart", frictionless, *CRACK_STEPS, "--set", "fault.crack.friction=0.3"],
                   frictionless, f"--restart {frictionless}: the checkpoint was written for another scene or other "
                   "--set values")
check(messages[0] == messages[1], f"the directory in use: the same line on both tracks: {messages[0]!r}")
