"""The mesh graded toward the faults' tips (fault.NAME.tip_size): before gmsh
meshes a .geo, a size field of at most tip_size + tip_grading * distance from
each fault's tips (its edges inside the body: points in 2D, curves in 3D),
the minimum over the faults as gmsh's background field
(cpp/domain/tip_grading.h)."""
from ..scene.input import SceneError


def _boundary_of(gmsh, entities, combined):
    """The tags of the entities on the boundary of `entities`: of their
    union (`combined`) or of each."""
    return {tag for _, tag in gmsh.model.getBoundary(entities, combined, False, False)}


def _outer_edges(gmsh, d):
    """The points (2D) or curves (3D) of the body's outer boundary."""
    faces = [(d - 1, tag) for tag in _boundary_of(gmsh, gmsh.model.getEntities(d), True)]
    return _boundary_of(gmsh, faces, False)


def _tips_of(gmsh, name, d):
    """The tips of the fault group `name` (dimension d - 2): the edges of
    its entities' union not on the outer boundary; None without the group
    (read_gmsh says so)."""
    entities = [(d - 1, int(t)) for dim, tag in gmsh.model.getPhysicalGroups(d - 1)
                if gmsh.model.getPhysicalName(dim, tag) == name
                for t in gmsh.model.getEntitiesForPhysicalGroup(dim, tag)]
    if not entities:
        return None
    outer = _outer_edges(gmsh, d)
    return [float(tag) for tag in sorted(_boundary_of(gmsh, entities, True)) if tag not in outer]


def grade_toward_tips(gmsh, scene):
    """Sets gmsh's background size field for the faults that give tip_size
    (on the model gmsh has open, before it meshes). Raises SceneError for a
    fault without a tip inside the body and for a .geo that sets size fields
    of its own (which the project's would replace)."""
    d, sizes = scene.mesh.dimension, []
    for name in sorted(scene.faults):  # as the C++'s std::map orders them
        fault = scene.faults[name]
        if fault.tip_size <= 0:
            continue
        key = f"{scene.file}: fault.{name}.tip_size: "
        tips = _tips_of(gmsh, name, d)
        if tips is None:  # no such group: read_gmsh names it
            continue
        if not tips:
            raise SceneError(key + "the fault has no tip inside the body (its edges are all on the outer boundary)")
        distance = gmsh.model.mesh.field.add("Distance")
        if not sizes and distance != 1:
            raise SceneError(key + f"{scene.mesh.file} sets size fields of its own, which the tips' would replace: "
                             "grade the tips there, or drop its fields")
        gmsh.model.mesh.field.setNumbers(distance, "PointsList" if d == 2 else "CurvesList", tips)
        if d == 3:  # points along each tip curve, 1/1000 of its length apart
            gmsh.model.mesh.field.setNumber(distance, "NumPointsPerCurve", 1000)
        size = gmsh.model.mesh.field.add("MathEval")
        gmsh.model.mesh.field.setString(size, "F", f"{fault.tip_size!r} + {fault.tip_grading!r} * F{distance}")
        sizes.append(size)
    if sizes:
        smallest = gmsh.model.mesh.field.add("Min")
        gmsh.model.mesh.field.setNumbers(smallest, "FieldsList", sizes)
        gmsh.model.mesh.field.setAsBackgroundMesh(smallest)
