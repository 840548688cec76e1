"""The pieces of a mesh split along faults (cells joined by shared nodes)
and what holds each as a rigid body: a piece that the clamps, prescribed
displacements, foundations and faults leave free to move has no unique
displacement, and a solve would move it without bound (a block held only
by a frictionless fault slid 4e10 m). Twin of cpp/domain/pieces.cpp."""
import numpy as np

from ..scene.input import point_text
from ..scene.scene import SceneError


def mesh_pieces(mesh):
    """The piece of every node of `mesh` (cells joined by their shared
    nodes), numbered 0, 1, ... in the order of their first cell."""
    # Imported here: scipy's sparse graphs take 0.1 s to import, which only
    # a mesh split along faults needs (the prototype's start-up).
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components
    nodes, cells = len(mesh.x), np.asarray(mesh.cells)
    first = np.repeat(cells[:, 0], cells.shape[1] - 1)
    graph = coo_matrix((np.ones(first.size), (first, cells[:, 1:].ravel())), shape=(nodes, nodes))
    _, label = connected_components(graph, directed=False)
    order = {}
    for component in label[cells[:, 0]]:
        order.setdefault(component, len(order))
    in_cells = np.zeros(nodes, dtype=bool)
    in_cells[cells.ravel()] = True
    return np.array([order[c] if used else -1 for c, used in zip(label, in_cells)], dtype=np.int64)


def held_motions(points, directions, dim, centre, size):
    """How many of a body's rigid motions (2D: 3; 3D: 6) the constraints
    (`points`, `directions`: (rows, dim)) hold: the rank of the rows
    direction . m(point) over the rigid motions m, taken about `centre`
    with rotations scaled by `size`."""
    m = 3 if dim == 2 else 6
    X = (np.asarray(points, dtype=float) - np.asarray(centre[:dim])) / size
    n = np.asarray(directions, dtype=float)
    if dim == 2:
        rows = np.column_stack([n[:, 0], n[:, 1], -X[:, 1] * n[:, 0] + X[:, 0] * n[:, 1]])
    else:
        rows = np.column_stack([n[:, 0], n[:, 1], n[:, 2], -X[:, 2] * n[:, 1] + X[:, 1] * n[:, 2],
                                X[:, 2] * n[:, 0] - X[:, 0] * n[:, 2], -X[:, 1] * n[:, 0] + X[:, 0] * n[:, 1]])
    G = rows.T @ rows  # the Gram matrix of the rows
    # Rank by Cholesky with diagonal pivoting, pivots below 1e-10 of the
    # largest diagonal counted as zero.
    floor, used, rank = 1e-10 * G.max(), np.zeros(m, dtype=bool), 0
    for _ in range(m):
        free = np.flatnonzero(~used)
        k = free[np.argmax(G[free, free])]
        if not G[k, k] > floor:
            break
        used[k], rank = True, rank + 1
        rest = np.flatnonzero(~used)
        G[np.ix_(rest, rest)] -= np.outer(G[rest, k], G[k, rest]) / G[k, k]
    return rank


def _point(mesh, node):
    return np.concatenate([mesh.x[node], np.zeros(3 - mesh.dim)])


def _facet_normal(mesh, nodes):
    """The normal of a facet (dim nodes), not normalised: its direction is
    all a constraint needs."""
    a, b = _point(mesh, nodes[0]), _point(mesh, nodes[1])
    if mesh.dim == 2:
        return np.array([a[1] - b[1], b[0] - a[0], 0.0])
    return np.cross(b - a, _point(mesh, nodes[2]) - a)


def _constrain(rows, mesh, where, n, every):
    """Adds the constraint (piece, other, x, n) along n at node, or along
    every axis (`every`); other = -1 is the ground."""
    piece, other, node = where
    for e in np.eye(3)[:mesh.dim] if every else [n]:
        rows.append((piece, other, _point(mesh, node), np.asarray(e, dtype=float)))


def _frictional(f):
    return f.friction > 0 or f.cohesion > 0 or f.tresca is not None


def _boundary_constraints(scene, mesh, piece, rows):
    """The ground's constraints: clamps and prescribed components, and
    foundations (along the facet's normal; every way with friction)."""
    for nodes, group in zip(mesh.facets, mesh.facet_group):
        spec = scene.boundaries.get(mesh.names[group])
        if spec is None:
            continue
        for node in nodes:
            if spec.mechanics == "contact":
                _constrain(rows, mesh, (piece[node], -1, node), _facet_normal(mesh, nodes),
                           _frictional(spec.contact.friction))
            if spec.mechanics == "displacement":
                for c in range(mesh.dim):
                    if spec.displacement[c] is not None:
                        rows.append((piece[node], -1, _point(mesh, node), np.eye(3)[c]))


def _fault_constraints(scene, mesh, faults, piece, rows):
    """Each fault's pairs: the + node's piece against the - node's, along
    the fault's normal (every way with friction)."""
    for f in faults:
        every = _frictional(scene.faults[f.name].friction)
        for plus_nodes, minus_nodes, n in zip(f.plus_facets, f.minus_facets, f.normals):
            for plus, minus in zip(plus_nodes, minus_nodes):
                if plus != minus:
                    _constrain(rows, mesh, (piece[plus], piece[minus], plus), n, every)


def _held(mesh, p, rows, is_held):
    """Whether piece p is held by the rows against the ground and held
    pieces."""
    chosen = [(x, n) for piece, other, x, n in rows
              if (piece == p and (other < 0 or is_held[other])) or (other == p and is_held[piece])]
    if not chosen:
        return False
    points = np.array([x for x, _ in chosen])
    low, high = points.min(axis=0), points.max(axis=0)
    size = float(np.max(high - low))
    motions = 3 if mesh.dim == 2 else 6
    return held_motions(points[:, :mesh.dim], np.array([n for _, n in chosen])[:, :mesh.dim], mesh.dim,
                        0.5 * (low + high), size if size > 0 else 1.0) == motions


def _piece_text(scene, mesh, faults, piece, p):
    """"the piece on its + side of fault.NAME (its node at (x, y))" for the
    first fault face in piece p."""
    for f in faults:
        for i in range(f.plus_facets.size):
            for nodes, side in ((f.plus_facets.ravel(), "+"), (f.minus_facets.ravel(), "-")):
                if f.plus_facets.ravel()[i] != f.minus_facets.ravel()[i] and piece[nodes[i]] == p:
                    return (f"{scene.file}: fault.{f.name}: the piece on its {side} side (its node at "
                            f"{point_text(_point(mesh, nodes[i]), mesh.dim)})")
    return f"{scene.file}: mesh: a piece of the mesh"


def refuse_free_pieces(scene, mesh, faults):
    """Refuses, with SceneError "FILE: fault.NAME: ...", the first piece of
    the split `mesh` that nothing holds: pieces held by a clamp, a
    prescribed displacement or a foundation (frictionless: along the
    facet's normal; with friction: every direction), then, in turn, pieces
    joined to held ones by a fault (frictionless: along its normal; with
    friction, cohesion or Tresca: every direction). Nothing to check in a
    scene without mechanics."""
    if scene.mechanics is None:
        return
    piece = mesh_pieces(mesh)
    rows = []
    _boundary_constraints(scene, mesh, piece, rows)
    _fault_constraints(scene, mesh, faults, piece, rows)
    is_held = np.zeros(piece.max() + 1, dtype=bool)
    changed = True
    while changed:
        changed = False
        for p in range(len(is_held)):
            if not is_held[p] and _held(mesh, p, rows, is_held):
                is_held[p], changed = True, True
    if is_held.all():
        return
    raise SceneError(_piece_text(scene, mesh, faults, piece, int(np.flatnonzero(~is_held)[0]))
                     + " is free to move as a rigid body: no clamp, displacement, foundation or fault with friction "
                       "holds all its rigid motions (a frictionless fault holds only its normal); hold it with a "
                       "displacement boundary, or give the fault friction")
