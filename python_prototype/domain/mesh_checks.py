"""The scene checked against its mesh before any solve
(cpp/domain/mesh_checks.cpp): every expression finite where it is used, a
foundation's normal outward, a flux or rate boundary planar, a well in the
mesh (and on its fault), each refused with SceneError naming its key; and
the normal and the measure of a planar boundary, which the flux and rate
conditions use."""
import numpy as np
from mpi4py import MPI
from dolfinx import mesh as dmesh
from dolfinx.cpp.mesh import entities_to_geometry

from ..scene.scene import SceneError, agree_on_error
from .fault_cells import well_cells
from .wells import locate_well, well_place


def check_expressions(scene, domain, comm):
    """Every expression of the scene evaluated where it is used (boundary
    values at the nodes of their boundary, a fault's pressure at the nodes
    of its + face, volume terms at the cell midpoints) at the first and the last time: NaN or inf is refused with
    SceneError naming its key, the same on every rank (cpp/domain/mesh_checks.h)."""
    mesh, d = domain.mesh, domain.mesh.topology.dim
    x = mesh.geometry.x
    midpoints = dmesh.compute_midpoints(mesh, d, np.arange(mesh.topology.index_map(d).size_local, dtype=np.int32))
    uses = []  # (key, expression, points, evaluated at the end time too)
    for name, b in sorted(scene.boundaries.items()):  # the order of the C++ std::map
        if name not in domain.boundaries:
            continue
        nodes = entities_to_geometry(mesh._mesh, d - 1, domain.boundaries[name], False).reshape(-1)
        at = x[nodes]
        for i, e in enumerate(b.displacement):
            if e is not None:
                uses.append((f"boundary.{name}.displacement.{'xyz'[i]}", e, at, True))
        for e in b.traction:
            uses.append((f"boundary.{name}.traction", e, at, True))
        if b.flow == "pressure":
            uses.append((f"boundary.{name}.pressure", b.pressure, at, True))
        if b.flow == "flux":
            uses.append((f"boundary.{name}.rate", b.rate, at, True) if b.rate is not None
                        else (f"boundary.{name}.flux", b.flux, at, True))
    for name, f in scene.faults.items():
        if f.pressure is not None and name in domain.faults:
            nodes = entities_to_geometry(mesh._mesh, d - 1, domain.faults[name].plus_facets, False).reshape(-1)
            uses.append((f"fault.{name}.pressure", f.pressure, x[nodes], True))
    for name, w in sorted(scene.wells.items()):
        uses.append((f"well.{name}.rate", w.rate, np.array([[w.position[0], w.position[1], w.bottom]]), True))
    if scene.mechanics and scene.mechanics.body_force:
        uses += [("mechanics.body_force", e, midpoints, True) for e in scene.mechanics.body_force]
    if scene.mechanics and scene.mechanics.pore_pressure is not None:
        uses.append(("mechanics.pore_pressure", scene.mechanics.pore_pressure, midpoints, True))
    if scene.flow:
        if scene.flow.source is not None:
            uses.append(("flow.source", scene.flow.source, midpoints, True))
        if scene.flow.permeability is not None:
            uses.append(("flow.permeability", scene.flow.permeability, midpoints, False))
        uses.append(("flow.initial_pressure", scene.flow.initial_pressure, midpoints, False))
    for name, r in sorted(scene.regions.items()):
        if r.where is not None:
            uses.append((f"region.{name}.where", r.where, midpoints, False))
        if r.body_force:
            uses += [(f"region.{name}.body_force", e, midpoints, True) for e in r.mechanics.body_force]
        if r.flow is not None and r.flow.permeability is not None:
            uses.append((f"region.{name}.permeability", r.flow.permeability, midpoints, False))

    index, message = len(uses), ""
    for k, (key, e, p, at_end) in enumerate(uses):
        for t in ((0.0, scene.end_time) if at_end else (0.0,)):
            with np.errstate(all="ignore"):
                v = np.broadcast_to(np.asarray(e(p[:, 0], p[:, 1], p[:, 2], t), dtype=float), (len(p),))
            bad = np.flatnonzero(~np.isfinite(v))
            if len(bad):
                i = bad[0]
                value = "NaN" if np.isnan(v[i]) else "inf" if v[i] > 0 else "-inf"
                where = ", ".join(f"{c:g}" for c in p[i, :d])
                index, message = k, f"{scene.file}: {key}: \"{e.text}\" is {value} at ({where}), t = {t:g}"
                break
        if index < len(uses):
            break
    agree_on_error(message, comm)
    _check_foundation_normals(scene, domain)
    for name, b in sorted(scene.boundaries.items()):
        if b.flow == "flux":
            planar_boundary(domain, name, f"{scene.file}: boundary.{name}.{'rate' if b.rate is not None else 'flux'}")
    for name, w in sorted(scene.wells.items()):
        locate_well(domain, w, f"{scene.file}: well.{name}.position")
        if w.fault and not len(well_cells(domain.faults[w.fault].cells, w)[0]):
            raise SceneError(f"{scene.file}: well.{name}.position: the well at {well_place(w, d)} is not on "
                             f"fault.{w.fault}")


class PlanarBoundary:
    """A planar boundary: its outward unit normal (3 components) and its
    measure (a length in 2D, an area in 3D), the same on every rank."""

    def __init__(self, normal, measure):
        self.normal, self.measure = normal, measure


def _facet_normals(vertices, cell_midpoints, d):
    """Outward unit normals and measures of exterior facets from their
    vertices (facets x d x 3) and the midpoints of their cells."""
    a, b = vertices[:, 0], vertices[:, 1]
    if d == 2:
        n = np.stack([b[:, 1] - a[:, 1], a[:, 0] - b[:, 0], np.zeros(len(a))], axis=1)
    else:
        n = np.cross(b - a, vertices[:, 2] - a)
    length = np.linalg.norm(n, axis=1)
    outward = np.sign(np.sum(n * (a - cell_midpoints), axis=1))
    outward[outward == 0] = 1
    return n * (outward / length)[:, None], length if d == 2 else length / 2


def _check_foundation_normals(scene, domain):
    """A foundation's normal is the direction in which its face moves to
    touch it: outward. One that points into the body (on average over the
    face) holds nothing, and the run would have no contact at all: refused,
    the same on every rank (collective; cpp/domain/mesh_checks.cpp)."""
    mesh, d = domain.mesh, domain.dim
    f_to_c = mesh.topology.connectivity(d - 1, d)
    for name, b in sorted(scene.boundaries.items()):
        if b.contact is None:
            continue
        facets = domain.boundaries[name]
        facets = facets[facets < mesh.topology.index_map(d - 1).size_local]
        nodes = entities_to_geometry(mesh._mesh, d - 1, facets, False)
        cells = np.array([f_to_c.links(f)[0] for f in facets], dtype=np.int32)
        midpoints = dmesh.compute_midpoints(mesh, d, cells) if len(cells) else np.zeros((0, 3))
        vertices = mesh.geometry.x[nodes].reshape(len(facets), d, 3)
        normals, measures = _facet_normals(vertices, midpoints, d)
        middle = vertices.mean(axis=1)
        nu = np.zeros((len(facets), 3))
        for i in range(d):
            nu[:, i] = np.broadcast_to(b.contact.normal[i](middle[:, 0], middle[:, 1], middle[:, 2], 0.0), len(facets))
        with np.errstate(all="ignore"):
            along = np.sum(nu * normals, axis=1) / np.linalg.norm(nu, axis=1)
        along = mesh.comm.allreduce(float(np.sum((measures * along)[np.isfinite(along)])))
        if along < 0:
            raise SceneError(f"{scene.file}: boundary.{name}.contact.normal: points into the body: it is the "
                             "direction in which the face moves to touch the foundation, outward from the body")


def planar_boundary(domain, name, key):
    """The outward normal and the measure of the boundary `name`; SceneError
    naming `key` when its facets do not lie in one plane (collective)."""
    mesh, d = domain.mesh, domain.dim
    facets = domain.boundaries[name]
    nodes = entities_to_geometry(mesh._mesh, d - 1, facets, False)
    f_to_c = mesh.topology.connectivity(d - 1, d)
    cells = np.array([f_to_c.links(f)[0] for f in facets], dtype=np.int32)
    midpoints = dmesh.compute_midpoints(mesh, d, cells) if len(cells) else np.zeros((0, 3))
    normals, measures = _facet_normals(mesh.geometry.x[nodes].reshape(len(facets), d, 3), midpoints, d)
    owned = facets < mesh.topology.index_map(d - 1).size_local
    local = np.append(np.sum(normals[owned] * measures[owned, None], axis=0), np.sum(measures[owned]))
    total = mesh.comm.allreduce(local)
    normal = total[:3] / np.linalg.norm(total[:3])
    deviation = mesh.comm.allreduce(float(np.max(np.linalg.norm(normals - normal, axis=1), initial=0.0)),
                                    op=MPI.MAX)
    if not deviation < 1e-6:
        raise SceneError(f"{key}: the boundary {name} is not planar (its facet normals differ from their mean by up "
                         f"to {deviation:g}); a flux or rate is prescribed on planar boundaries only")
    return PlanarBoundary(normal, float(total[3]))
