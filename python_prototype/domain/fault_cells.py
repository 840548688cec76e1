"""The cells of a fault's own flow (cpp/domain/fault_cells.cpp): each facet
of the fault that the split opened is one cell of the fault (a segment in
2D, a triangle in 3D), where the fault's pressure p_f is one unknown. Two
cells meet at an edge (a node in 2D, an edge of two nodes in 3D); an edge
of one cell only is an end of the fault: on the outer boundary (its group
given) or a tip inside the rock. Computed on rank 0 from the split mesh
(faults.py), the same on every rank afterwards."""
import dataclasses
import itertools

import numpy as np


@dataclasses.dataclass
class FaultEdges:
    """Edges of a fault's cells: links (the two cells that share the edge)
    or ends (the one cell of an edge on the outer boundary). Distances run
    from each cell's centroid to the edge's midpoint (the two-point flux,
    docs/theory.md "Flow in a fault"); an edge's measure is 1 in 2D (per
    metre of thickness)."""
    cells: np.ndarray      # (edges, 2) for links, (edges, 1) for ends
    measures: np.ndarray   # (edges,)
    distances: np.ndarray  # like cells
    points: np.ndarray     # (edges, 3) midpoints

    @staticmethod
    def of(rows, width):
        """From (cells, measure, distances, midpoint) rows."""
        return FaultEdges(np.array([r[0] for r in rows], dtype=np.int64).reshape(-1, width),
                          np.array([r[1] for r in rows], dtype=float),
                          np.array([r[2] for r in rows], dtype=float).reshape(-1, width),
                          np.array([r[3] for r in rows], dtype=float).reshape(-1, 3))


@dataclasses.dataclass
class FaultCells:
    """A fault's cells, the links between them and its ends on the outer
    boundary (each with its boundary group's name)."""
    keys: np.ndarray       # (cells, d) the + face's nodes, sorted (the split numbering)
    twins: np.ndarray      # (cells, d) each key's node on the - face (itself at a tip)
    normals: np.ndarray    # (cells, 3) the unit normal into the + side
    measures: np.ndarray   # (cells,) length or area
    centroids: np.ndarray  # (cells, 3)
    vertices: np.ndarray   # (cells, d, 3) the + face's nodes, in the order of keys
    links: FaultEdges
    ends: FaultEdges
    end_groups: list
    # one-cell edges inside the body: a tip, or an edge where the split
    # separated the fault's cells at another fault (fault_network)
    inner: FaultEdges
    # the links the split cut where another fault crosses or ends on this
    # one (two inner edges at one point): one plane to its mechanics
    cut: FaultEdges


@dataclasses.dataclass
class FaultJunction:
    """Where faults' cells meet at one edge other than as one fault's link:
    where faults cross or one ends on another (an intersection in the fault
    network). Its members are every cell with an edge there."""
    point: np.ndarray  # the edge's midpoint (3,)
    measure: float     # the edge's length in 3D, 1 in 2D
    faults: list       # per member: its fault (an index into the faults given)
    cells: list        # per member: its cell in that fault
    distances: list    # per member: from its centroid to the point


@dataclasses.dataclass
class FaultNetwork:
    """A network of faults: each fault's links but those at junctions, and
    the junctions."""
    links: list      # FaultEdges per fault
    junctions: list  # FaultJunction


def fault_network(faults):
    """The network of `faults` (FaultCells), the faults whose cells
    exchange fluid: a point where more than one of their edges (links and
    inner edges, matched by their midpoints, which the split's copies of a
    node reproduce exactly) meet is a junction of all their cells, and its
    links leave the faults' links (docs/theory.md, "Flow in a fault
    network")."""
    at = {}  # the edges (fault, edges, index) at each midpoint
    for f, cells in enumerate(faults):
        for edges in (cells.links, cells.inner):
            for e, point in enumerate(edges.points.tolist()):
                at.setdefault(tuple(point), []).append((f, edges, e))
    links = []
    for cells in faults:  # in the order of the fault's links: the same sums as alone
        kept = [len(at[tuple(point)]) == 1 for point in cells.links.points.tolist()]
        l = cells.links
        links.append(FaultEdges(l.cells[kept].reshape(-1, 2), l.measures[kept], l.distances[kept].reshape(-1, 2),
                                l.points[kept].reshape(-1, 3)))
    junctions = []
    for point, edges in sorted(at.items()):
        if len(edges) == 1:
            continue
        j = FaultJunction(np.array(point), float(edges[0][1].measures[edges[0][2]]), [], [], [])
        for f, e, index in edges:
            j.faults += [f] * e.cells.shape[1]
            j.cells += e.cells[index].tolist()
            j.distances += e.distances[index].tolist()
        junctions.append(j)
    return FaultNetwork(links, junctions)


def _edge_geometry(x, nodes):
    """An edge's measure (1 for a node) and midpoint."""
    points = x[list(nodes)]
    measure = 1.0 if len(nodes) == 1 else float(np.linalg.norm(points[1] - points[0]))
    return measure, points.mean(axis=0)


def _cell_geometry(x, nodes):
    """A cell's measure (a segment's length, a triangle's area) and centroid."""
    p = x[list(nodes)]
    if len(nodes) == 2:
        return float(np.linalg.norm(p[1] - p[0])), p.mean(axis=0)
    return 0.5 * float(np.linalg.norm(np.cross(p[1] - p[0], p[2] - p[0]))), p.mean(axis=0)


def _boundary_groups(mesh):
    """The group name of every boundary edge (a sorted tuple of d - 1
    nodes) of the outer boundary's named facets; the first group wins."""
    groups = {}
    for facet, group in zip(mesh.facets.tolist(), np.asarray(mesh.facet_group).tolist()):
        for edge in itertools.combinations(sorted(facet), mesh.dim - 1):
            groups.setdefault(edge, mesh.names[group])
    return groups


def fault_cells(mesh, split):
    """The cells of the SplitFault `split` in the split InputMesh `mesh`."""
    d = mesh.dim
    x = np.zeros((len(mesh.x), 3))
    x[:, :d] = mesh.x
    opened = np.flatnonzero(np.any(split.plus_facets != split.minus_facets, axis=1))
    order = np.argsort(split.plus_facets[opened], axis=1)
    keys = np.take_along_axis(split.plus_facets[opened], order, axis=1)
    twins = np.take_along_axis(split.minus_facets[opened], order, axis=1)
    geometry = [_cell_geometry(x, k) for k in keys.tolist()]
    edges = {}
    for c, key in enumerate(keys.tolist()):
        for edge in itertools.combinations(key, d - 1):
            edges.setdefault(edge, []).append(c)
    boundary = _boundary_groups(mesh)
    links, ends, groups, inner = [], [], [], []
    for edge, cells in sorted(edges.items()):
        measure, middle = _edge_geometry(x, edge)
        row = (cells, measure, [float(np.linalg.norm(middle - geometry[c][1])) for c in cells], middle)
        if len(cells) == 2:
            links.append(row)
        elif len(cells) == 1 and edge in boundary:
            ends.append(row)
            groups.append(boundary[edge])
        elif len(cells) == 1:
            inner.append(row)
    first, cut = {}, []  # the inner edge first met at each midpoint
    for cells, measure, distances, middle in inner:
        other = first.setdefault(tuple(middle.tolist()), (cells, distances))
        if other[0] is not cells:
            cut.append((other[0] + cells, measure, other[1] + distances, middle))
    return FaultCells(keys, twins, np.asarray(split.normals)[opened].reshape(-1, 3), np.array([g[0] for g in geometry]),
                      np.array([g[1] for g in geometry]).reshape(-1, 3), x[keys].reshape(-1, d, 3),
                      FaultEdges.of(links, 2), FaultEdges.of(ends, 1), groups, FaultEdges.of(inner, 1),
                      FaultEdges.of(cut, 2))


def _on_segments(vertices, point):
    """Per segment (vertices: cells x 2 x 3) the distance of `point` to it."""
    a, b = vertices[:, 0], vertices[:, 1]
    ab = b - a
    s = np.clip(np.sum((point - a) * ab, axis=1) / np.sum(ab * ab, axis=1), 0.0, 1.0)
    return np.linalg.norm(a + s[:, None] * ab - point, axis=1)


def _on_triangles(vertices, well):
    """Per triangle (vertices: cells x 3 x 3) whether the well's vertical
    segment (at (x, y) from z = bottom to top) meets it (its barycentric
    coordinates within round-off of [0, 1]); a triangle parallel to it is
    not met."""
    a, b, c = vertices[:, 0], vertices[:, 1], vertices[:, 2]
    x, y = well.position[0], well.position[1]
    u, v = b - a, c - a
    det = u[:, 0] * v[:, 1] - u[:, 1] * v[:, 0]
    with np.errstate(divide="ignore", invalid="ignore"):
        s = ((x - a[:, 0]) * v[:, 1] - (y - a[:, 1]) * v[:, 0]) / det
        r = (u[:, 0] * (y - a[:, 1]) - u[:, 1] * (x - a[:, 0])) / det
    z = a[:, 2] + s * u[:, 2] + r * v[:, 2]
    tol = 1e-9
    inside = (s >= -tol) & (r >= -tol) & (s + r <= 1 + tol) & (np.abs(det) > 1e-12 * np.sum(u * u, axis=1))
    return inside & (z >= well.bottom) & (z <= well.top)


def well_cells(cells, well):
    """The fault cells a well meets and the share of its rate each takes
    (equal shares where it meets several, at a shared node or edge): in 2D
    the cells within 1e-6 of their length of the well's point, in 3D the
    triangles its vertical segment crosses; empty when it meets none."""
    if cells.vertices.shape[1] == 2:
        point = np.array([well.position[0], well.position[1], 0.0])
        hit = np.flatnonzero(_on_segments(cells.vertices, point) <= 1e-6 * cells.measures)
    else:
        hit = np.flatnonzero(_on_triangles(cells.vertices, well))
    return hit, np.full(len(hit), 1.0 / max(len(hit), 1))
