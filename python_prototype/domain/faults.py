"""Faults: an input simplex mesh split along interior facet groups, on rank 0
before dolfinx distributes it (cpp/domain/faults.cpp). Each fault node gets
one node per piece of the cells around it that the faults separate (two on
one fault, the + side's a new node at the same point; three or four where
faults cross or end on one another), so the faults' faces become faces of
the mesh that the contact can pair; the fault's edges inside the body (its
tips) stay shared. A fault facet whose nodes are all tips (a fault of one
facet in 2D, a triangle with every node on a patch's rim in 3D) stays shared
too: its two faces are the same nodes."""
import dataclasses
import math

import numpy as np

from ..scene.input import SceneError
from .mesh_topology import cells_of, facet_key, local_index, topology_of


@dataclasses.dataclass
class InputMesh:
    """The input mesh as read on rank 0 (the arrays of a gmsh file that
    read_gmsh (gmsh_mesh.py) hands to dolfinx)."""
    dim: int
    x: np.ndarray            # (nodes, dim) coordinates
    cells: np.ndarray        # (cells, dim+1) node indices
    facets: np.ndarray       # (facets, dim) node indices of the facets of named groups
    facet_group: np.ndarray  # per facet, an index into names
    names: list


@dataclasses.dataclass
class FaultRequest:
    """What is asked: a fault's facet group and its normal hint, a direction
    the fault's normal is oriented along (n . hint > 0)."""
    name: str
    hint: tuple


@dataclasses.dataclass
class SplitFault:
    """One fault after the split. Row k of plus_facets, minus_facets and
    normals is the fault's k-th facet in input order."""
    name: str
    # (fault facets, dim) node indices in the split numbering: each facet's
    # face on the + side (the side the normal points into), and on the - side
    plus_facets: np.ndarray
    minus_facets: np.ndarray
    normals: np.ndarray  # (fault facets, 3) unit normals oriented by the hint, into the + side
    # (doubled nodes, 2): (its index on the + side, its index on the - side),
    # in increasing order of the - side's (the input) index
    pairs: np.ndarray
    tips: np.ndarray  # the fault nodes kept shared (the fault's edges inside the body; each copy of one
    #                   another fault splits), sorted
    # (intersections, 2): (input node, the other fault's index) where this fault
    # crosses, ends on or is ended on by another, in increasing node order
    meets: np.ndarray = dataclasses.field(default_factory=lambda: np.zeros((0, 2), dtype=np.int64))


def _mean_point(mesh, nodes):
    """The mean of the nodes' coordinates (a node, a facet's midpoint, a
    cell's centroid), z = 0 in 2D."""
    p = [0.0, 0.0, 0.0]
    for v in nodes:
        for i in range(mesh.dim):
            p[i] += float(mesh.x[v, i]) / len(nodes)
    return p


def _point_text(p, d):
    """"(x, y)" or "(x, y, z)", as C++ prints it (an ostream's default, {:g})."""
    return "(" + ", ".join(f"{v:g}" for v in p[:d]) + ")"


def _dot(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def _facet_normal(mesh, nodes):
    """A facet's unit normal, either way: 2D, its segment turned by -90
    degrees; 3D, the cross product of its edges from the first node."""
    d = mesh.dim
    a, b = ([float(mesh.x[nodes[k], i] - mesh.x[nodes[0], i]) for i in range(d)] + [0.0] * (3 - d)
            for k in (1, d - 1))  # in 2D the one edge twice (b unused)
    n = ([a[1], -a[0], 0.0] if d == 2 else
         [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]])
    length = math.sqrt(_dot(n, n))
    return [v / length for v in n]


@dataclasses.dataclass
class _OrientedFault:
    """A fault's facets before the split: their input indices (in input
    order), normals oriented by the hint, and the cell on each side."""
    facets: list = dataclasses.field(default_factory=list)
    normals: list = dataclasses.field(default_factory=list)
    plus_cells: list = dataclasses.field(default_factory=list)
    minus_cells: list = dataclasses.field(default_factory=list)


def _group_index(mesh, name, key):
    """The index of the group `name` in the mesh's names."""
    if name in mesh.names:
        return mesh.names.index(name)
    known = ", ".join(mesh.names) or "none"
    raise SceneError(f"{key}: the mesh has no group {name} (its facet groups: {known})")


def _side(mesh, topology, cell, nodes, n):
    """How far cell `cell`'s centroid lies from the facet through `nodes`,
    along n: the + cell is the one on the side n points into."""
    centroid = _mean_point(mesh, topology.cells[cell])
    on = _mean_point(mesh, nodes[:1])
    return _dot(n, [centroid[0] - on[0], centroid[1] - on[1], centroid[2] - on[2]])


def _orient_fault(mesh, topology, request, key):
    """The facets of the group `request.name`, each between two cells, with
    its normal oriented by the hint (scaled to unit length, so that the
    parallel test does not depend on its length) and its + and - cells."""
    d = mesh.dim
    group = _group_index(mesh, request.name, key)
    hint = [float(h) for h in request.hint]
    length = math.sqrt(_dot(hint, hint))
    if length > 0:
        hint = [h / length for h in hint]
    fault = _OrientedFault()
    for f in np.flatnonzero(np.asarray(mesh.facet_group) == group).tolist():
        nodes = mesh.facets[f].tolist()
        cells = cells_of(topology, facet_key(nodes))
        at = " at " + _point_text(_mean_point(mesh, nodes), d)
        if len(cells) == 1:
            raise SceneError(f"{key}: the group {request.name} lies on the outer boundary{at} "
                             "(a fault is inside the body)")
        if len(cells) != 2:
            embed = "Curve{..} In Surface{..}" if d == 2 else "Surface{..} In Volume{..}"
            raise SceneError(f"{key}: the group {request.name} is not in the mesh's cells (its facets are no faces "
                             f"of them): embed it (gmsh: {embed})")
        n = _facet_normal(mesh, nodes)
        along = _dot(n, hint)
        if abs(along) < 1e-12:
            raise SceneError(f"{key}.normal: the hint is parallel to the fault{at}: give a normal that crosses it")
        if along < 0:
            n = [-v for v in n]
        first_plus = _side(mesh, topology, cells[0], nodes, n) > _side(mesh, topology, cells[1], nodes, n)
        fault.facets.append(f)
        fault.normals.append(n)
        fault.plus_cells.append(cells[0 if first_plus else 1])
        fault.minus_cells.append(cells[1 if first_plus else 0])
    if not fault.facets:
        raise SceneError(f"{key}: the group {request.name} has no facets")
    return fault


def _fault_nodes(mesh, faults):
    """The fault facets through each fault node, (fault, facet k), by node in
    increasing order; within a node, in request order."""
    nodes = {}
    for f, fault in enumerate(faults):
        for k, facet in enumerate(fault.facets):
            for v in mesh.facets[facet].tolist():
                nodes.setdefault(v, []).append((f, k))
    return dict(sorted(nodes.items()))


def _refuse_shared_facets(mesh, oriented, faults, key_prefix):
    """Refuses a facet in two faults' groups: one curve (3D: surface) given
    to two physical groups, which the split could not give two faults."""
    fault_of = {}
    for f, fault in enumerate(oriented):
        for facet in fault.facets:
            nodes = mesh.facets[facet].tolist()
            first = fault_of.setdefault(facet_key(nodes), f)
            if first != f:
                at = _point_text(_mean_point(mesh, nodes), mesh.dim)
                raise SceneError(f"{key_prefix}{faults[first].name}: the physical groups {faults[first].name} and "
                                 f"{faults[f].name} share the facet at {at}: a "
                                 f"{'curve' if mesh.dim == 2 else 'surface'} belongs to one fault's group only")


def _fault_keys(mesh, faults):
    """The facets of all faults."""
    return {facet_key(mesh.facets[f]) for fault in faults for f in fault.facets}


class _NodeStar:
    """The cells around a node (ascending) and the component of each: cells
    connected through the facets that hold the node and lie on no fault,
    numbered in the order of their first cell."""

    def __init__(self, topology, v, keys):
        self.cells = topology.node_cells[v]
        self.component = [-1] * len(self.cells)
        self.count = 0
        position = {c: i for i, c in enumerate(self.cells)}
        for first in range(len(self.cells)):
            if self.component[first] >= 0:
                continue
            self.component[first] = self.count
            stack = [self.cells[first]]
            while stack:
                cell = stack.pop()
                for other in _neighbours(topology, cell, v, keys):
                    if self.component[position[other]] < 0:
                        self.component[position[other]] = self.count
                        stack.append(other)
            self.count += 1

    def component_of(self, cell):
        return self.component[self.cells.index(cell)]


def _neighbours(topology, cell, v, keys):
    """The cells that share with `cell` a facet through node v on no fault."""
    nodes = topology.cells[cell].tolist()
    found = []
    for j, u in enumerate(nodes):
        if u == v:
            continue
        key = facet_key(nodes[:j] + nodes[j + 1:])
        if key in keys:
            continue
        found += [other for other in cells_of(topology, key) if other != cell]
    return found


def _check_sides(mesh, star, fault, facets, v, key):
    """Refuses + and - cells of the fault's facets through a split node v
    (`facets`) in one component of its star: the hint's side of the fault
    flips at v. Where each facet's two cells hold together, v is on the
    fault's edge (a tip line that crosses another fault, in 3D), which
    another fault split: nothing to check."""
    plus = {star.component_of(fault.plus_cells[k]) for k in facets}
    minus = {star.component_of(fault.minus_cells[k]) for k in facets}
    separates = any(star.component_of(fault.plus_cells[k]) != star.component_of(fault.minus_cells[k])
                    for k in facets)
    if separates and plus & minus:
        raise SceneError(f"{key}: the normal hint orients the fault inconsistently at "
                         f"{_point_text(_mean_point(mesh, [v]), mesh.dim)} (the fault turns past the hint there: "
                         "give a hint that crosses all of it the same way)")


class _Splitter:
    """The split of the fault nodes, one node at a time: the input mesh
    (renumbered in place), its topology, the oriented faults and their
    facets, the faults' results so far and the nodes added."""

    def __init__(self, mesh, topology, faults, key_prefix, split):
        self.mesh, self.topology, self.faults, self.key_prefix, self.split = mesh, topology, faults, key_prefix, split
        self.keys, self.added = _fault_keys(mesh, faults), []

    def copies(self, star, first, v):
        """The node of each component of v's star: v itself for the
        component of the cell `first` (with one fault, its - side), a new
        node at v's point for each other, in the order of the components."""
        keep, node_of = star.component_of(first), []
        for c in range(star.count):
            node_of.append(v if c == keep else len(self.mesh.x) + len(self.added))
            if c != keep:
                self.added.append(self.mesh.x[v])
        return node_of

    def split_node(self, v, through):
        """Node v gets one node per component of its star (the cells around
        it that the faults leave connected); each fault's facets through v
        pair the nodes of their + and - cells' components (a tip where they
        are one)."""
        mesh, faults, split = self.mesh, self.faults, self.split
        star = _NodeStar(self.topology, v, self.keys)
        by_fault = {}
        for f, k in through:
            by_fault.setdefault(f, []).append(k)
        if star.count > 2 and len(by_fault) == 1:
            raise SceneError(f"{self.key_prefix}{split[through[0][0]].name}: the fault branches or crosses itself at "
                             f"{_point_text(_mean_point(mesh, [v]), mesh.dim)} ({star.count} pieces meet there): "
                             "give each branch a fault (a physical group) of its own")
        node_of = [v]
        if star.count > 1:
            for f, facets in by_fault.items():
                _check_sides(mesh, star, faults[f], facets, v, self.key_prefix + split[f].name)
            node_of = self.copies(star, faults[through[0][0]].minus_cells[through[0][1]], v)
        for cell, component in zip(star.cells, star.component):
            mesh.cells[cell, local_index(self.topology, cell, v)] = node_of[component]
        for f, facets in by_fault.items():
            pairs = []
            for k in facets:
                pair = (node_of[star.component_of(faults[f].plus_cells[k])],
                        node_of[star.component_of(faults[f].minus_cells[k])])
                if pair[0] != pair[1] and pair not in pairs:
                    pairs.append(pair)
            split[f].pairs += pairs
            if not pairs:  # a tip: each copy of v on f (a rim crossing another fault)
                split[f].tips += sorted({node_of[star.component_of(faults[f].plus_cells[k])] for k in facets})
            split[f].meets += [(v, g) for g in by_fault if g != f]


def _split_nodes(mesh, topology, faults, nodes, key_prefix, split):
    """Each fault node (in increasing order) stays shared where the faults'
    cells around it hold together (a tip), or gets one node per piece of
    its star (two on one fault: its + side's cells take a new node; three
    or four where faults cross or end on one another)."""
    splitter = _Splitter(mesh, topology, faults, key_prefix, split)
    for v, through in nodes.items():
        splitter.split_node(v, through)
    if splitter.added:
        mesh.x = np.vstack([mesh.x, splitter.added])


def _face(mesh, topology, cell, nodes):
    """The input facet through `nodes` as cell `cell` numbers it after the split."""
    return [int(mesh.cells[cell, local_index(topology, cell, v)]) for v in nodes]


def _fault_faces(mesh, topology, fault, split):
    """A fault's two faces after the split, from its + and - cells."""
    for k, facet in enumerate(fault.facets):
        nodes = mesh.facets[facet].tolist()
        split.plus_facets.append(_face(mesh, topology, fault.plus_cells[k], nodes))
        split.minus_facets.append(_face(mesh, topology, fault.minus_cells[k], nodes))


def _renumber_facets(mesh, topology, on_fault):
    """Keeps the facets of no fault, each as its (first) cell numbers it after
    the split: where a fault reaches the outer boundary, the boundary splits
    with it. A facet that is no face of a cell is kept as it is."""
    facets, groups = [], []
    for f, group in enumerate(np.asarray(mesh.facet_group).tolist()):
        if on_fault[f]:
            continue
        nodes = mesh.facets[f].tolist()
        cells = cells_of(topology, facet_key(nodes))
        facets.append(_face(mesh, topology, cells[0], nodes) if cells else nodes)
        groups.append(group)
    mesh.facets = np.array(facets, dtype=np.int64).reshape(-1, mesh.dim)
    mesh.facet_group = np.array(groups, dtype=np.int32)


def split_along_faults(mesh, faults, key_prefix):
    """Splits `mesh` in place along each requested fault and returns the
    faults (SplitFault) in request order. A split node's new copies (one on
    one fault, two or three where faults cross or end on one another) are
    appended to x (in increasing order of the input index) and the cells and
    boundary facets of their pieces are renumbered; the faults' facets leave
    facets and facet_group (names keeps its entries). Raises SceneError, one
    line "KEY_PREFIXNAME: ..." (e.g. key_prefix "scene.toml: fault."), for a
    group that is missing, empty or on the outer boundary, a hint parallel to
    the fault, a hint that orients the fault inconsistently, a facet in two
    faults' groups, and one fault that branches or crosses itself."""
    mesh.x = np.array(mesh.x, dtype=np.float64).reshape(-1, mesh.dim)
    mesh.cells = np.array(mesh.cells, dtype=np.int64).reshape(-1, mesh.dim + 1)
    mesh.facets = np.array(mesh.facets, dtype=np.int64).reshape(-1, mesh.dim)
    topology = topology_of(mesh.dim, mesh.cells, len(mesh.x))
    oriented = [_orient_fault(mesh, topology, request, key_prefix + request.name) for request in faults]
    split = [SplitFault(request.name, [], [], fault.normals, [], [], []) for request, fault in zip(faults, oriented)]
    _refuse_shared_facets(mesh, oriented, faults, key_prefix)
    nodes = _fault_nodes(mesh, oriented)
    _split_nodes(mesh, topology, oriented, nodes, key_prefix, split)
    on_fault = np.zeros(len(mesh.facet_group), dtype=bool)
    for fault, result in zip(oriented, split):
        _fault_faces(mesh, topology, fault, result)
        on_fault[fault.facets] = True
    _renumber_facets(mesh, topology, on_fault)
    d = mesh.dim
    return [SplitFault(s.name, np.array(s.plus_facets, dtype=np.int64).reshape(-1, d),
                       np.array(s.minus_facets, dtype=np.int64).reshape(-1, d),
                       np.array(s.normals, dtype=np.float64).reshape(-1, 3),
                       np.array(s.pairs, dtype=np.int64).reshape(-1, 2), np.array(sorted(s.tips), dtype=np.int64),
                       np.array(s.meets, dtype=np.int64).reshape(-1, 2))
            for s in split]
