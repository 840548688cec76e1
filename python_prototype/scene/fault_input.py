"""The readers of what a scene puts on and in its mesh (cpp/scene/fault_input.h):
the boundaries' conditions [boundary.NAME] (with a contact's foundation and
friction), the faults [fault.NAME] and the wells [well.NAME]. Mirrors
cpp/scene/fault_input.cpp key by key."""
import math
import os

from .expression import Expression
from .input import CouplingScheme, FaultFlow, MeshType, TimeScheme, name_of
from .schema import BoundarySpec, ClosureSpec, ContactSpec, FaultSpec, FrictionSpec, WellSpec, builtin_boundary_names


def _read_friction(s):
    """friction, cohesion or tresca of a contact table or a fault (FrictionSpec)."""
    f = FrictionSpec(friction=s.number("friction", 0.0), cohesion=s.number("cohesion", 0.0))
    if not (f.friction >= 0 and math.isfinite(f.friction)):
        s.fail("friction", "must be a finite number >= 0 (the Coulomb coefficient)")
    if not (f.cohesion >= 0 and math.isfinite(f.cohesion)):
        s.fail("cohesion", "must be a finite number >= 0 (Pa)")
    if s.has("tresca"):
        if s.has("friction") or s.has("cohesion"):
            s.fail("tresca", "give tresca (a given bound) or friction and cohesion (Coulomb), not both")
        f.tresca = s.number("tresca")
        if not (f.tresca >= 0 and math.isfinite(f.tresca)):
            s.fail("tresca", "must be a finite number >= 0 (Pa)")
    return f


def _read_contact(c, d):
    """contact = { gap = .., normal = [..], friction.. }: the foundation of a
    contact boundary."""
    gap = c.expression("gap")
    if gap is None:
        c.fail("gap", "missing (the gap g_a to the foundation)")
    if gap.depends_on_time:
        c.fail("gap", "must not depend on t")
    normal = c.expression_vector("normal", d)
    if any(n.depends_on_time for n in normal):
        c.fail("normal", "must not depend on t")
    # A normal that varies in space is checked at every contact node.
    if all(n.is_constant for n in normal):
        length = sum(n(0, 0, 0, 0) ** 2 for n in normal)
        if not (length > 0 and math.isfinite(length)):
            c.fail("normal", "must be a non-zero finite vector")
    if gap.is_constant and gap(0, 0, 0, 0) < 0:
        c.fail("gap", "must be >= 0")
    friction = _read_friction(c)
    c.finish()
    return ContactSpec(gap, normal, friction)


def _read_boundary(s, d):
    b = BoundarySpec()
    # A traction may load a contact boundary (the fluid pressure on an open
    # fracture face); otherwise the mechanics conditions exclude each other.
    count = sum(s.has(k) for k in ("clamp", "displacement", "traction", "contact"))
    if count > 1 and not (count == 2 and s.has("traction") and s.has("contact")):
        s.fail("clamp", "give at most one of clamp, displacement, traction, contact (or traction with contact)")
    if s.has("clamp"):
        if not s.boolean("clamp", False):
            s.fail("clamp", "must be true when given")
        b.mechanics = "displacement"
        b.displacement = [Expression(0.0) if i < d else None for i in range(3)]
    if s.has("displacement"):
        b.mechanics = "displacement"
        c = s.section("displacement", True)
        b.displacement = [c.expression(n) if i < d else None for i, n in enumerate("xyz")]
        c.finish()
        if not any(b.displacement):
            s.fail("displacement", "give at least one component (x, y or z)")
    if s.has("traction"):
        b.mechanics = "traction"
        b.traction = s.expression_vector("traction", d)
    if s.has("contact"):
        b.mechanics = "contact"
        b.contact = _read_contact(s.section("contact", True), d)
    for key in ("friction", "cohesion", "tresca"):
        if s.has(key):
            s.fail(key, f"acts on a contact: give it in contact = {{ .., {key} = .. }}")
    b.pore_pressure_load = s.boolean("pore_pressure_load", False)
    if b.pore_pressure_load and not b.contact:
        s.fail("pore_pressure_load", "loads a contact boundary only (the face of a fracture)")

    if s.has("pressure") + s.has("flux") + s.has("rate") > 1:
        s.fail("rate" if s.has("rate") else "flux", "give at most one of pressure, flux, rate")
    p = s.expression("pressure")
    if p is not None:
        b.flow, b.pressure = "pressure", p
    f = s.expression("flux")
    if f is not None:
        b.flow, b.flux = "flux", f
    r = s.expression("rate")
    if r is not None:
        if r.depends_on_space:
            s.fail("rate", "the total rate through the boundary depends on t only (use flux for one that varies "
                   "along it)")
        b.flow, b.rate = "flux", r
    s.finish()
    return b


def read_boundaries(boundaries, scene):
    """[boundary.NAME]: built-in meshes know their boundaries' names; a gmsh
    mesh's are checked against its physical groups when the domain is made."""
    d = scene.mesh.dimension
    names = builtin_boundary_names(d)
    for name in boundaries.keys():
        if scene.mesh.type != MeshType.gmsh and name not in names:
            boundaries.fail(name, f"unknown boundary name (a {name_of(scene.mesh.type)} has {', '.join(names)})")
        b = _read_boundary(boundaries.section(name, True), d)
        if not scene.mechanics and b.mechanics != "traction_free":
            boundaries.fail(name, "mechanics boundary condition in a scene without [mechanics]")
        if not scene.flow and b.flow != "no_flow":
            boundaries.fail(name, "flow boundary condition in a scene without [flow]")
        if b.pore_pressure_load and not scene.coupling and not (scene.mechanics and scene.mechanics.pore_pressure):
            boundaries.fail(name + ".pore_pressure_load", "needs a pore pressure: a coupled scene, or "
                            "mechanics.pore_pressure")
        scene.boundaries[name] = b
    boundaries.finish()


def read_wells(wells, scene):
    """[well.NAME]: position = [x, y], rate = expr of t; in 3D a vertical
    segment from bottom to top (z). Whether it lies in the mesh is checked
    when the domain is made."""
    for name in sorted(wells.keys()):
        s = wells.section(name, True)
        if not scene.flow:
            wells.fail(name, "a well in a scene without [flow]")
        position = s.number_vector("position", 2)
        bottom = top = 0.0
        if scene.mesh.dimension == 3:
            bottom, top = s.number("bottom"), s.number("top")
            if not top > bottom:
                s.fail("top", "must be above bottom (the well is the vertical segment from bottom to top)")
        rate = s.expression("rate")
        if rate is None:
            s.fail("rate", "missing (the volumetric rate, injection positive)")
        if rate.depends_on_space:
            s.fail("rate", "the rate of a well depends on t only")
        fault = s.string("fault", "")
        if fault and fault not in scene.faults:
            s.fail("fault", f'no fault "{fault}" in the scene ([fault.{fault}])')
        if fault and scene.faults[fault].flow != FaultFlow.conduit:
            s.fail("fault", f'fault.{fault} is no conduit (flow = "conduit"): a well injects into the rock or a '
                   "conduit fault")
        s.finish()
        scene.wells[name] = WellSpec(position, rate, bottom, top, fault)
    wells.finish()


def _read_fault(s, scene):
    """fault.NAME: the gap, the fluid pressure in the fault or the pore
    pressure beside it, what the fault is to the flow, and the normal's hint."""
    f = FaultSpec(gap=s.expression("gap") or Expression(0.0))
    if f.gap.depends_on_time:
        s.fail("gap", "must not depend on t")
    f.pressure = s.expression("pressure")
    f.pore_pressure_load = s.boolean("pore_pressure_load", False)
    if f.pore_pressure_load and f.pressure is not None:
        s.fail("pore_pressure_load", "give pressure or pore_pressure_load, not both")
    if f.pore_pressure_load and not scene.flow and not (scene.mechanics and scene.mechanics.pore_pressure):
        s.fail("pore_pressure_load", "needs a pore pressure: [flow], or mechanics.pore_pressure")
    f.flow = s.choice("flow", FaultFlow, FaultFlow.transparent)
    if f.flow != FaultFlow.transparent and not scene.flow:
        s.fail("flow", f'"{name_of(f.flow)}" in a scene without [flow]')
    if f.flow == FaultFlow.pressure and f.pressure is None:
        s.fail("pressure", 'missing (flow = "pressure" holds the fault at this pressure)')
    if f.flow == FaultFlow.conduit:
        # A conduit's faces carry its own fluid pressure p_f: any other
        # pressure on them would be a second, contradictory one.
        if f.pressure is not None:
            s.fail("pressure", 'not with flow = "conduit": the fault\'s own fluid pressure p_f pushes on its faces')
        if f.pore_pressure_load:
            s.fail("pore_pressure_load", 'not with flow = "conduit": the fault\'s own fluid pressure p_f pushes on '
                   "its faces, not the rock's")
        _read_conduit(s, scene, f)
    elif s.has("permeability") or s.has("normal_permeability"):
        s.fail("permeability" if s.has("permeability") else "normal_permeability",
               f'only a conduit fault (flow = "conduit") has one; this fault is "{name_of(f.flow)}"')
    d = scene.mesh.dimension
    f.normal = s.number_vector("normal", d) if s.has("normal") else [0.0] * (d - 1) + [1.0]
    length = sum(n * n for n in f.normal)
    if not (length > 0 and math.isfinite(length)):
        s.fail("normal", "must be a non-zero finite vector")
    f.friction = _read_friction(s)
    _read_tips(s, scene, f)
    s.finish()
    return f


def _read_tips(s, scene, f):
    """fault.NAME.tip_size and tip_grading: the mesh graded toward the
    fault's tips by gmsh, which meshes a .geo only."""
    if not s.has("tip_size"):
        if s.has("tip_grading"):
            s.fail("tip_grading", "needs tip_size (the mesh size at the tips)")
        return
    f.tip_size = s.number("tip_size")
    if not (f.tip_size > 0 and math.isfinite(f.tip_size)):
        s.fail("tip_size", "must be a finite number > 0 (m)")
    f.tip_grading = s.number("tip_grading", f.tip_grading)
    if not (f.tip_grading > 0 and math.isfinite(f.tip_grading)):
        s.fail("tip_grading", "must be a finite number > 0 (the size's growth per metre away from the tips)")
    if os.path.splitext(scene.mesh.file)[1] != ".geo":
        s.fail("tip_size", f"needs a .geo mesh file, which gmsh meshes here ({scene.mesh.file} is meshed already: "
               "grade its tips in gmsh)")


def _read_conduit(s, scene, f):
    """A conduit fault's hydraulic keys (docs/user-guide.md, "Flow in a
    fault"): its aperture where closed, w_r > 0, the permeability across
    its faces, k_n > 0 or "inf", its own tangential permeability k_f > 0
    (else the cubic law), and the closure of its aperture."""
    if scene.time_scheme == TimeScheme.bdf2 and scene.coupling and scene.coupling.scheme in (
            CouplingScheme.multirate, CouplingScheme.multirate_two_pass):
        s.fail("flow", '"conduit" with time.scheme = "bdf2" and a multirate coupling.scheme: the fault\'s '
               'storage is BDF2 in the single-rate schemes only ("fixed-stress", "monolithic")')
    f.residual_aperture = s.number("residual_aperture")
    if not (f.residual_aperture > 0 and math.isfinite(f.residual_aperture)):
        s.fail("residual_aperture", "must be a finite number > 0 (m)")
    if s.has("normal_permeability") and s.table["normal_permeability"] == "inf":
        s.used.add("normal_permeability")
    else:
        f.normal_permeability = s.number("normal_permeability", math.inf)
        if not f.normal_permeability > 0:
            s.fail("normal_permeability", 'must be > 0 (m^2) or "inf"')
    f.permeability = s.number("permeability", 0.0)
    if s.has("permeability") and not (f.permeability > 0 and math.isfinite(f.permeability)):
        s.fail("permeability", "must be a finite number > 0 (m^2, the fault's own; without it the cubic law's "
               "w_h^2 / 12)")
    if s.has("closure") and not scene.mechanics:
        s.fail("closure", "needs [mechanics]: the closed aperture follows the fault's normal stress")
    if s.has("closure"):
        f.closure = _read_closure(s.section("closure", True))


def _read_closure(c):
    """closure = { V_m = .., K_ni = .. }: the Barton-Bandis closure of a
    conduit fault, whose normal stress the mechanics gives."""
    closure = ClosureSpec(V_m=c.number("V_m"))
    if not (closure.V_m > 0 and math.isfinite(closure.V_m)):
        c.fail("V_m", "must be a finite number > 0 (m, the largest closure)")
    closure.K_ni = c.number("K_ni")
    if not (closure.K_ni > 0 and math.isfinite(closure.K_ni)):
        c.fail("K_ni", "must be a finite number > 0 (Pa/m, the initial normal stiffness)")
    c.finish()
    return closure


def read_faults(faults, scene):
    """[fault.NAME]: faults lie inside a gmsh mesh, on groups that are not
    boundaries. That NAME is an interior group of the mesh, and the gap
    >= 0 at its nodes, are checked where the mesh is split along it."""
    for name in faults.keys():
        s = faults.section(name, True)
        if scene.mesh.type != MeshType.gmsh:
            faults.fail(name, 'a fault is an interior physical group of a gmsh mesh (mesh.type = "gmsh")')
        if name in scene.boundaries:
            faults.fail(name, f"also given as [boundary.{name}]: a physical group is a boundary or a fault, not both")
        scene.faults[name] = _read_fault(s, scene)
    faults.finish()
