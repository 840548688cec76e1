"""Scene -> Domain (cpp/domain/create_domain.cpp): the built-in rectangle
of crossed triangles or box of tetrahedra, with boundaries left/right (x),
bottom/top (y) in 2D and left/right (x), front/back (y), bottom/top (z) in
3D; or a gmsh file (gmsh_mesh.py)."""
import numpy as np
from dolfinx import mesh as dmesh

from ..scene.input import MeshType
from .domain import Domain
from .gmsh_mesh import read_gmsh
from .regions import locate_regions
from .working_ranks import built_in_cells, working_communicator


def _box_faces(d):
    """(axis, lower side?) of each named face of an axis-aligned box."""
    if d == 2:
        return {"left": (0, True), "right": (0, False), "bottom": (1, True), "top": (1, False)}
    return {"left": (0, True), "right": (0, False), "front": (1, True), "back": (1, False),
            "bottom": (2, True), "top": (2, False)}


def create_domain(scene, world):
    """The mesh of `scene` on the working ranks of `world`
    (working_ranks.py) with its named boundaries; None on a rank that waits
    (collective on world)."""
    m = scene.mesh
    if m.type == MeshType.gmsh:
        return read_gmsh(scene, world)
    comm = working_communicator(world, built_in_cells(m), scene.solver.cells_per_rank)
    if comm is None:
        return None  # this rank waits
    if m.type == MeshType.rectangle:
        mesh = dmesh.create_rectangle(comm, [m.lower, m.upper], m.cells, dmesh.CellType.triangle,
                                      dmesh.GhostMode.shared_facet, diagonal=dmesh.DiagonalType.crossed)
    else:
        mesh = dmesh.create_box(comm, [m.lower, m.upper], m.cells, dmesh.CellType.tetrahedron,
                                dmesh.GhostMode.shared_facet)
    d = m.dimension
    mesh.topology.create_connectivity(d - 1, d)
    boundaries = {}
    for name, (axis, lower) in _box_faces(d).items():
        value = m.lower[axis] if lower else m.upper[axis]
        tol = 1e-10 * (m.upper[axis] - m.lower[axis])
        boundaries[name] = np.sort(dmesh.locate_entities_boundary(
            mesh, d - 1, lambda x, a=axis, v=value, tol=tol: np.abs(x[a] - v) < tol)).astype(np.int32)
    return Domain(mesh, boundaries, locate_regions(scene, mesh, None))
