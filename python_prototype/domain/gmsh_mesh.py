"""A gmsh mesh (.geo meshed, or .msh) read on rank 0 like the C++ reader
and distributed by dolfinx (cpp/domain/gmsh_mesh.cpp): its cells (a
degenerate one refused), the named physical groups of dimension d-1 as
boundaries and those of cells as regions, and the mesh split along the
scene's faults (faults.py), whose two faces become exterior facets."""
import dataclasses
import math
import os

import numpy as np
import ufl
from dolfinx import io, mesh as dmesh
from dolfinx.cpp.graph import AdjacencyList_int32

from ..scene.input import point_text
from ..scene.scene import SceneError
from .domain import Domain, Fault
from .fault_cells import fault_cells
from .faults import FaultRequest, InputMesh, split_along_faults
from .mesh_cache import mesh_cache_file, store_mesh
from .pieces import refuse_free_pieces
from .regions import locate_regions, regions_of_groups
from .tip_grading import grade_toward_tips
from .working_ranks import wait_quietly, working_communicator


def _cell_groups(gmsh, d, element_tags):
    """The input indices of the cells of each named physical group of cells."""
    position = {int(t): i for i, t in enumerate(element_tags)}
    groups = {}
    for dim, tag in gmsh.model.getPhysicalGroups(d):
        cells = groups.setdefault(gmsh.model.getPhysicalName(dim, tag) or f"group{tag}", [])
        for entity in gmsh.model.getEntitiesForPhysicalGroup(dim, tag):
            etags, _ = gmsh.model.mesh.getElementsByType(2 if d == 2 else 4, entity)
            cells += [position[int(t)] for t in etags]
    return groups


@dataclasses.dataclass
class _GmshData:
    """What rank 0 reads from a gmsh file: nodes (N, d), simplices, the
    facets of each named physical group of dimension d-1 (an index into
    names each), the region of each cell (input order) from the physical
    groups of cells the scene's regions name, and the node pairs and
    normals of the scene's faults after the split, in the order of
    scene.faults: their faces are the last two facet groups each, + then -."""
    x: np.ndarray
    cells: np.ndarray
    facets: np.ndarray
    facet_group: np.ndarray
    names: list
    cell_region: object
    faults: list = dataclasses.field(default_factory=list)


def _check_fault_groups(gmsh, scene):
    """Each [fault.NAME] names a physical group of dimension d-1 of the
    file; SceneError naming the key otherwise (gmsh open)."""
    d = scene.mesh.dimension
    groups = [(dim, gmsh.model.getPhysicalName(dim, tag) or f"group{tag}")
              for dim, tag in gmsh.model.getPhysicalGroups()]
    known = ", ".join(group for _, group in groups) or "none"
    for name in scene.faults:
        key = f"{scene.file}: fault.{name}: "
        dimension = -1
        for group_dim, group in groups:
            if group == name and (dimension < 0 or group_dim == d - 1):
                dimension = group_dim
        if dimension < 0:
            raise SceneError(f"{key}no physical group {name} in {scene.mesh.file} (it has {known})")
        if dimension != d - 1:
            raise SceneError(f"{key}the physical group {name} is of dimension {dimension}; a fault is of dimension "
                             f"{d - 1}" + (" (a curve in the surface)" if d == 2 else " (a surface in the volume)"))


def _open_mesh(gmsh, scene):
    """Opens the scene's mesh in gmsh: a .msh as it is; a .geo from the
    mesh cache where it holds it (mesh_cache.py), else meshed (graded
    toward the faults' tips, its sizes times mesh.size_factor), refined
    mesh.refine times and, with a cache, stored there and read back."""
    file = scene.mesh.file
    cached = mesh_cache_file(gmsh, scene)
    if cached is not None and os.path.exists(cached):
        gmsh.open(cached)
        return
    gmsh.open(file)
    if os.path.splitext(file)[1] == ".geo":
        grade_toward_tips(gmsh, scene)
        # After open(): the factor scales the .geo's sizes and its fields,
        # times the .geo's own factor, if it sets one.
        own = gmsh.option.getNumber("Mesh.MeshSizeFactor")
        gmsh.option.setNumber("Mesh.MeshSizeFactor", own * scene.mesh.size_factor)
        gmsh.model.mesh.generate(scene.mesh.dimension)
    for _ in range(scene.mesh.refine):
        gmsh.model.mesh.refine()
    if cached is not None:
        store_mesh(gmsh, cached)
        gmsh.clear()
        gmsh.open(cached)  # as every later run reads it


def _read_gmsh_file(scene):
    """Rank 0: nodes, simplices, the facets of each physical group of
    dimension d-1 and the region of each cell, split along the faults."""
    import gmsh
    file, d = scene.mesh.file, scene.mesh.dimension
    gmsh.initialize()
    gmsh.option.setNumber("General.Terminal", 0)
    try:
        _open_mesh(gmsh, scene)
        tags, coords, _ = gmsh.model.mesh.getNodes(-1, -1, False, False)
        index = {int(t): i for i, t in enumerate(tags)}
        x = np.asarray(coords).reshape(-1, 3)[:, :d].copy()
        element_tags, node_tags = gmsh.model.mesh.getElementsByType(2 if d == 2 else 4)
        cells = np.array([index[int(t)] for t in node_tags], dtype=np.int64).reshape(-1, d + 1)
        cell_region = regions_of_groups(scene, len(element_tags), _cell_groups(gmsh, d, element_tags))
        facets, groups, names = [], [], []
        for dim, tag in gmsh.model.getPhysicalGroups(d - 1):
            names.append(gmsh.model.getPhysicalName(dim, tag) or f"group{tag}")
            for entity in gmsh.model.getEntitiesForPhysicalGroup(dim, tag):
                etags, ntags = gmsh.model.mesh.getElementsByType(1 if d == 2 else 2, entity)
                facets += [index[int(t)] for t in ntags]
                groups += [len(names) - 1] * len(etags)
        _check_fault_groups(gmsh, scene)
    except SceneError:
        gmsh.finalize()
        raise
    except Exception as e:
        gmsh.finalize()
        raise SceneError(f"{file}: cannot read the gmsh file: {e}") from None
    gmsh.finalize()
    if len(cells) == 0:
        kind = "triangles" if d == 2 else "tetrahedra"
        raise SceneError(f"{file}: no {kind} in the mesh (mesh.dimension = {d})")
    x, cells, facets = _drop_unused_nodes(x, cells, np.array(facets, dtype=np.int64).reshape(-1, d))
    data = _GmshData(x, cells, facets, np.array(groups, dtype=np.int32), names, cell_region)
    _check_cells(scene, data)
    _split_faults(scene, data)
    return data


def _drop_unused_nodes(x, cells, facets):
    """Only the nodes of the cells, numbered in their order in the file: the
    mesh's input numbering is then 0 .. N-1, the rows of the output."""
    used = np.unique(cells)
    index = np.full(len(x), -1, dtype=np.int64)
    index[used] = np.arange(len(used))
    return x[used], index[cells], index[facets]


def _check_cells(scene, data):
    """Refuses a cell of (nearly) zero area or volume, measured against its
    longest edge: the stiffness and the mass balance of such a cell are
    round-off, and a split along a fault cannot tell its sides apart."""
    d = scene.mesh.dimension
    edges = np.zeros((len(data.cells), d, 3))
    edges[:, :, :d] = data.x[data.cells[:, 1:]] - data.x[data.cells[:, :1]]
    longest = np.max(np.sqrt(np.sum(edges ** 2, axis=2)), axis=1)
    a, b, e = edges[:, 0], edges[:, 1], edges[:, -1]
    if d == 2:
        measure = np.abs(a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0]) / 2
    else:
        measure = np.abs(a[:, 0] * (b[:, 1] * e[:, 2] - b[:, 2] * e[:, 1])
                         - a[:, 1] * (b[:, 0] * e[:, 2] - b[:, 2] * e[:, 0])
                         + a[:, 2] * (b[:, 0] * e[:, 1] - b[:, 1] * e[:, 0])) / 6
    bad = np.flatnonzero(measure < 1e-10 * longest ** d)
    if len(bad):
        at = point_text(data.x[data.cells[bad[0], 0]], d)
        raise SceneError(f"{scene.mesh.file}: a cell of zero {'area' if d == 2 else 'volume'} at {at}: "
                         "the mesh is degenerate there (check its sizes; at a crack's tip gmsh 4.8's "
                         "Mesh.RandomFactor = 1e-12 or another Mesh.Algorithm avoids it)")


def _pair_normals(split, d):
    """The unit normal at each node pair of a split fault: the mean of the
    normals of its facets that hold the pair's + node (summed in the C++
    order, so that both tracks have the same bits)."""
    total = {}
    for k, n in enumerate(split.normals.tolist()):
        for node in split.plus_facets[k, :d].tolist():
            s = total.setdefault(node, [0.0, 0.0, 0.0])
            for j in range(3):
                s[j] += n[j]
    normals = np.zeros((len(split.pairs), 3))
    for p, plus in enumerate(split.pairs[:, 0].tolist()):
        n = total[plus]
        length = math.sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2])
        normals[p] = [c / length for c in n]
    return normals


def _split_faults(scene, data):
    """Splits the mesh along the scene's faults (faults.py): their faces
    become the last facet groups, + and - of each fault in turn."""
    if not scene.faults:
        return
    d = scene.mesh.dimension
    mesh = InputMesh(d, data.x, data.cells, data.facets, data.facet_group, data.names)
    requests = [FaultRequest(name, tuple(fault.normal) + (0.0,) * (3 - d)) for name, fault in scene.faults.items()]
    split = split_along_faults(mesh, requests, f"{scene.file}: fault.")
    refuse_free_pieces(scene, mesh, split)
    facets, groups = [mesh.facets], [mesh.facet_group]
    for f in split:
        # A facet whose nodes are all tips stays inside the body (faults.py):
        # it is no face, on either side.
        opened = np.flatnonzero(np.any(f.plus_facets != f.minus_facets, axis=1))
        for face, side in ((f.plus_facets, "+"), (f.minus_facets, "-")):
            groups.append(np.full(len(opened), len(mesh.names), dtype=np.int32))
            mesh.names.append(f"fault.{f.name}{side}")
            facets.append(face[opened])
        data.faults.append((f.pairs, _pair_normals(f, d), fault_cells(mesh, f)))
    data.x, data.cells, data.names = mesh.x, mesh.cells, mesh.names
    data.facets = np.concatenate(facets).astype(np.int64).reshape(-1, d)
    data.facet_group = np.concatenate(groups).astype(np.int32)


def _check_boundary_names(scene, groups):
    """Every boundary the scene names is one of the mesh's physical groups
    `groups` (of dimension d-1, the faults' faces not among them)."""
    for name in scene.boundaries:
        if name not in groups:
            known = ", ".join(groups) or "none"
            raise SceneError(f"{scene.file}: boundary.{name}: unknown boundary name ({scene.mesh.file} has "
                             f"physical groups {known})")


def read_gmsh(scene, world):
    """A gmsh mesh read on rank 0 and distributed by dolfinx; boundaries are
    its named physical groups of dimension d-1. SceneError, the same on
    every rank, for what it refuses: a file gmsh cannot read, no cells or a
    degenerate one, a fault that names no group of dimension d-1, a piece
    nothing holds, an unknown boundary name (collective on world). The mesh
    lives on the working ranks (working_ranks.py); None on a rank that
    waits."""
    d = scene.mesh.dimension
    data, error = None, None
    if world.rank == 0:
        try:
            data = _read_gmsh_file(scene)
        except SceneError as e:
            error = str(e)
    # Every rank learns the outcome, the group names, the cells and the
    # faults' node pairs and normals (rank 0's); the others wait for rank 0
    # asleep.
    wait_quietly(world.Ibarrier())
    error, names, faults, cells = world.bcast((error, data.names, data.faults, len(data.cells))
                                              if data else (error, None, None, 0), root=0)
    if error:
        raise SceneError(error)
    count = len(names) - 2 * len(scene.faults)
    _check_boundary_names(scene, names[:count])
    comm = working_communicator(world, cells, scene.solver.cells_per_rank)
    if comm is None:
        return None  # this rank waits
    if comm.rank != 0:
        data = _GmshData(np.zeros((0, d)), np.zeros((0, d + 1), dtype=np.int64), np.zeros((0, d), dtype=np.int64),
                         np.zeros(0, dtype=np.int32), names, None)
    cell = ufl.triangle if d == 2 else ufl.tetrahedron
    mesh = dmesh.create_mesh(comm, data.cells, data.x, ufl.Mesh(ufl.VectorElement("Lagrange", cell, 1)))
    mesh.topology.create_connectivity(d - 1, d)
    mesh.topology.create_entities(d - 1)
    entities, values = io.distribute_entity_data(mesh._mesh, d - 1, data.facets, data.facet_group)
    tags = dmesh.meshtags_from_entities(mesh, d - 1, AdjacencyList_int32(entities), values.astype(np.int32))

    def group_facets(g):
        return np.sort(tags.indices[tags.values == g]).astype(np.int32)
    # The faults' faces are the last groups, + and - of each fault in turn.
    boundaries = {names[g]: group_facets(g) for g in range(count)}
    domain_faults = {name: Fault(group_facets(count + 2 * k), group_facets(count + 2 * k + 1), *faults[k])
                     for k, name in enumerate(scene.faults)}
    return Domain(mesh, boundaries, locate_regions(scene, mesh, data.cell_region), domain_faults)
