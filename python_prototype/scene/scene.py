"""A scene: one TOML file that says what to simulate (docs/user-guide.md, "Scene reference").

Mirrors cpp/scene/scene.cpp and the readers of its tables (physics_input.py,
fault_input.py, run_input.py) key by key: the same defaults, the same checks in
the same order, and the same one-line messages `<file>: <key>: <message>`;
the choices are read into the enums of input.py, the tables by section.py's
Section, into the schema of schema.py (whose names importers also find here).
Tables are read in sorted key order, as toml++ (a sorted map) does, so the
order of the boundaries is the same.
"""
import math
import os
import re
import tomllib

from mpi4py import MPI

from .expression import CONSTANTS, FUNCTIONS, VARIABLES, Expression, ExpressionError
from .fault_input import read_boundaries, read_faults, read_wells
from .input import MeshType, SceneError
from .physics_input import read_physics, read_regions
from .run_input import read_output, read_reference, read_solver, read_time
from .schema import (MAX_STEPS, AdaptiveSpec, BoundarySpec, ClosureSpec, ContactSpec, CouplingSpec,  # noqa: F401
                     FaultSpec, FlowSpec, FrictionSpec, MechanicsSpec, MeshSpec, ReferenceSpec, RegionSpec, Scene,
                     SolverSpec, WellSpec, builtin_boundary_names)
from .section import Section, apply_override, identifiers, substitute_names


def agree_on_error(message, comm):
    """Bad input found on some ranks only: every rank raises SceneError with
    the message of the lowest rank that found one, so that no rank is left
    waiting in a collective call (cpp/scene/scene.h). Collective."""
    owner = comm.allreduce(comm.rank if message else comm.size, op=MPI.MIN)
    if owner < comm.size:
        raise SceneError(comm.bcast(message, root=owner))


def _read_mesh(s, scene_file):
    m = MeshSpec(type=s.choice("type", MeshType))
    if m.type in (MeshType.rectangle, MeshType.box):
        d = 2 if m.type == MeshType.rectangle else 3
        m.dimension = d
        m.lower = s.number_vector("lower", d) if s.has("lower") else [0.0] * d
        m.upper = s.number_vector("upper", d)
        n = s.number_vector("cells", d)
        for i in range(d):
            if m.upper[i] <= m.lower[i]:
                s.fail("upper", "must be above mesh.lower in every direction")
            if n[i] < 1 or n[i] != math.floor(n[i]):
                s.fail("cells", "must be positive integers")
            m.cells.append(int(n[i]))
        # Refused before any allocation (cpp/scene/scene.cpp): about 4 kB per
        # triangle and 25 kB per tetrahedron measured with direct solvers.
        simplices = (4.0 if d == 2 else 6.0) * math.prod(n)
        need = simplices * (4e3 if d == 2 else 25e3)
        have = os.sysconf("SC_PHYS_PAGES") * os.sysconf("SC_PAGE_SIZE")
        if have > 0 and need > have:
            s.fail("cells", f"{simplices:.2g} cells need about {need / 1e9:.2g} GB of memory; "
                   f"this machine has {have / 1e9:.2g} GB")
    else:
        name = s.string("file")
        # Mesh files are looked up next to the scene, then in meshes/.
        here = os.path.dirname(scene_file)
        for candidate in (os.path.join(here, name), os.path.join(here, "..", "meshes", name), name):
            if os.path.exists(candidate):
                m.file = os.path.normpath(candidate)
                break
        if not m.file:
            s.fail("file", "mesh file not found: " + name)
        m.dimension = s.integer("dimension", 2)
        if m.dimension not in (2, 3):
            s.fail("dimension", "must be 2 or 3")
        # Each refinement splits every simplex into 2^d: nested meshes, as
        # the studies' references need (tools/study.py maps nodes by position).
        m.refine = s.integer("refine", 0)
        if not 0 <= m.refine <= 6:
            s.fail("refine", "must be an integer in [0, 6]")
        # Any fineness between the refinements' halvings (a 3D study's levels:
        # each refinement costs 8x), at the price of meshes that do not nest.
        m.size_factor = s.number("size_factor", 1.0)
        if not (m.size_factor > 0 and math.isfinite(m.size_factor)):
            s.fail("size_factor", "must be a finite number > 0")
        if s.has("size_factor") and os.path.splitext(m.file)[1] != ".geo":
            s.fail("size_factor", f"needs a .geo mesh file, which gmsh meshes here ({m.file} is meshed already: "
                   "use mesh.refine)")
    s.finish()
    return m


def read_scene(file, overrides=()):
    """Reads and validates a scene; `overrides` are "key.path=value" strings."""
    root = _parse_scene(file, overrides)
    scene = Scene(file=file)
    top = Section(root, "", file)
    top.set_names(_read_names(top.section("expressions", False)))
    _read_meta(top, scene)
    scene.mesh = _read_mesh(top.section("mesh", True), file)
    top.set_axes(scene.mesh.dimension)
    read_physics(top, scene)
    read_time(top, scene)
    read_output(top.section("output", False), scene)
    read_solver(top.section("solver", False), scene.mesh.dimension, scene.solver)
    read_boundaries(top.section("boundary", False), scene)
    read_faults(top.section("fault", False), scene)
    read_wells(top.section("well", False), scene)
    read_regions(top.section("region", False), root, scene)
    if top.has("reference"):
        read_reference(top.section("reference", True), scene)
    top.finish()
    return scene


def _parse_scene(file, overrides):
    """The scene file as a dict, with the --set overrides applied."""
    if not os.path.isfile(file):
        raise SceneError(f"{file}: scene file not found")
    try:
        with open(file, "rb") as f:
            root = tomllib.load(f)
    except tomllib.TOMLDecodeError as e:
        m = re.search(r"\(at line (\d+), column \d+\)", str(e))
        line, description = m.group(1) if m else "1", re.sub(r" \(at .*\)$", "", str(e))
        raise SceneError(f"{file}:{line}: invalid TOML: {description}") from None
    for o in overrides:
        apply_override(root, o, file)
    return root


# The identifiers an expression already knows (expression.py: variables,
# constants and functions), which no name may take.
_RESERVED = set(VARIABLES) | set(CONSTANTS) | set(FUNCTIONS)


def _resolve_name(name, given, resolved, path, s):
    """The text of `name` with the names it uses substituted, resolving them
    first (depth first); `path` holds the names being resolved, so that a
    cycle is refused naming it (C++'s resolve_name)."""
    if name in resolved:
        return resolved[name]
    if name in path:
        cycle = " -> ".join(path[path.index(name):] + [name])
        s.fail(path[0], f"the names refer to one another in a cycle ({cycle})")
    path.append(name)
    for used in identifiers(given[name]):
        if used in given:
            _resolve_name(used, given, resolved, path, s)
    path.pop()
    resolved[name] = substitute_names(given[name], resolved)
    return resolved[name]


def _read_names(s):
    """[expressions]: names for numbers and expressions of x, y, z, t, each
    usable in every expression of the scene and in the other names' (in any
    order, without a cycle); each is parsed as every expression is."""
    given, resolved = {}, {}
    for name in s.keys():
        if identifiers(name) != [name] or name in _RESERVED:
            s.fail(name, "not a name: a letter or _ then letters, digits or _, none of x, y, z, t, pi and the "
                   "functions of an expression")
        n = s.node(name)
        if s.is_number(n):
            given[name] = Expression(float(n)).text
        elif isinstance(n, str):
            given[name] = n
        else:
            s.fail(name, "must be a number or an expression string")
    for name, text in sorted(given.items()):
        _resolve_name(name, given, resolved, [], s)
        try:
            Expression(resolved[name], text)
        except ExpressionError as e:
            s.fail(name, str(e))
    s.finish()
    return resolved


def _read_meta(top, scene):
    """[scene]: the name (the file's stem by default) and description."""
    meta = top.section("scene", False)
    scene.name = meta.string("name", os.path.splitext(os.path.basename(scene.file))[0])
    scene.description = meta.string("description", "")
    meta.finish()
