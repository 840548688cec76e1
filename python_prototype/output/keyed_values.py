"""The unknowns of a field under names that no partition changes
(cpp/output/keyed_values.h): each DOF named by the input indices of the
mesh entity it sits on, so that a checkpoint written on one partition
restores on any other (output/checkpoint.py); and a signature of the mesh,
so that a checkpoint of another mesh is refused."""
import dolfinx.la
import numpy as np

from ..domain.domain import vertex_input_indices


def _facet_names(mesh, vertex_input):
    """Per local facet: the sorted input indices of its vertices, and the
    parity (+-1) of the permutation from the order of the partition's global
    vertex numbering (dolfinx's orientation of the facet) to the sorted one."""
    f = mesh.topology.dim - 1
    mesh.topology.create_connectivity(f, 0)
    vertices = mesh.topology.connectivity(f, 0).array.reshape(-1, f + 1)
    global_index = mesh.topology.index_map(0).local_to_global(vertices.ravel()).reshape(vertices.shape)
    in_global_order = np.take_along_axis(vertex_input[vertices], np.argsort(global_index, axis=1), axis=1)
    inversions = sum((in_global_order[:, a] > in_global_order[:, b]).astype(int)
                     for a in range(f + 1) for b in range(a + 1, f + 1))
    return np.sort(vertex_input[vertices], axis=1), np.where(inversions % 2 == 0, 1.0, -1.0)


def _entity_names(mesh, V):
    """The input names of the entities V's DOF blocks sit on (rows; a
    vertex, a facet's sorted vertices or a cell) and the sign that turns a
    DOF to the orientation of its name."""
    tdim, layout = mesh.topology.dim, V.dofmap.dof_layout
    dim = next(d for d in range(tdim + 1) if layout.num_entity_dofs(d) > 0)
    if layout.num_entity_dofs(dim) != 1:
        raise RuntimeError("checkpoint: a space that is not one DOF per vertex, facet or cell")
    per_cell = layout.num_dofs
    blocks = V.dofmap.index_map.size_local + V.dofmap.index_map.num_ghosts
    names = np.full((blocks, tdim if dim == tdim - 1 else 1), -1, dtype=np.int64)
    sign = np.ones(blocks)
    cell_dofs = V.dofmap.list.array.reshape(-1, per_cell)
    vertex_input = vertex_input_indices(mesh)
    if dim == tdim - 1:
        facet_names, facet_sign = _facet_names(mesh, vertex_input)
        cell_facets = mesh.topology.connectivity(tdim, dim).array.reshape(-1, per_cell)
    for k in range(per_cell):
        block = cell_dofs[:, layout.entity_dofs(dim, k)[0]]
        if dim == 0:
            names[block, 0] = vertex_input[mesh.topology.connectivity(tdim, 0).array.reshape(-1, per_cell)[:, k]]
        elif dim == tdim:
            names[block, 0] = mesh.topology.original_cell_index[:len(block)]
        else:
            names[block], sign[block] = facet_names[cell_facets[:, k]], facet_sign[cell_facets[:, k]]
    return names, sign


def _entries(mesh, part):
    """Per local entry of part's space: its name (rows) and sign."""
    V = part.space
    bs = V.dofmap.index_map_bs
    names, sign = _entity_names(mesh, V)
    if bs > 1:  # a vector at a vertex: the vertex's input index times bs plus the component
        names = (names[:, :1] * bs + np.arange(bs)).reshape(-1, 1)
    return names, np.repeat(sign, bs)


def keyed_values(mesh, part, unknowns):
    """The owned entries of `part` in `unknowns`: (names, values)."""
    names, sign = _entries(mesh, part)
    owned = part.space.dofmap.index_map.size_local * part.space.dofmap.index_map_bs
    position = np.arange(owned) if part.position is None else np.asarray(part.position)[:owned]
    return names[:owned].copy(), sign[:owned] * unknowns[position]


def _rows(keys):
    """Rows of int64 as one comparable value each."""
    keys = np.ascontiguousarray(keys, dtype=np.int64)
    return keys.view(np.dtype((np.void, keys.itemsize * keys.shape[1]))).ravel()


def _update_ghosts(space, position, unknowns):
    """The ghost entries of a function space's values in `unknowns` (at
    `position`) from their owners: stored values may be each rank's owned
    ones only (a checkpoint kept in memory, which coupling.fallback hands
    between schemes), and a ghost left as it was would enter the next
    assembly (collective)."""
    index_map, bs = space.dofmap.index_map, space.dofmap.index_map_bs
    v = dolfinx.la.vector(index_map, bs)
    v.array[:] = unknowns[position]
    v.scatter_forward()
    owned = index_map.size_local * bs
    unknowns[position[owned:]] = v.array[owned:]


def restore_values(mesh, part, stored, unknowns):
    """Sets the owned entries of `part` in `unknowns` from the stored
    (names, values), every rank's or this rank's own, then the ghost
    entries from their owners; returns how many owned entries were not
    found (collective)."""
    names, sign = _entries(mesh, part)
    stored_names, stored_values = stored
    if stored_names.shape[1] != names.shape[1]:
        return part.space.dofmap.index_map.size_local * part.space.dofmap.index_map_bs
    stored_rows = _rows(stored_names)
    order = np.argsort(stored_rows)
    stored_rows = stored_rows[order]
    mine = _rows(names)
    at = np.minimum(np.searchsorted(stored_rows, mine), len(stored_rows) - 1)
    found = stored_rows[at] == mine if len(stored_rows) else np.zeros(len(mine), dtype=bool)
    position = np.arange(len(mine)) if part.position is None else np.asarray(part.position)
    unknowns[position[found]] = sign[found] * stored_values[order[at[found]]]
    _update_ghosts(part.space, position, unknowns)
    owned = part.space.dofmap.index_map.size_local * part.space.dofmap.index_map_bs
    return owned - int(np.count_nonzero(found[:owned]))


def mesh_signature(mesh):
    """The global numbers of nodes and cells and a sum of the node
    coordinates weighted by input index (the same as the C++ solver's)."""
    g = mesh.geometry
    owned = g.index_map().size_local
    input_index = np.asarray(g.input_global_indices, dtype=np.int64)[:owned]
    weights = 1 + (input_index[:, None] * 3 + np.arange(g.dim)) % 1009
    total = mesh.comm.allreduce(float(np.sum(g.x[:owned, :g.dim] * weights)))
    return np.array([g.index_map().size_global, mesh.topology.index_map(mesh.topology.dim).size_global, total],
                    dtype=float)


def mesh_difference(stored, current):
    """How the mesh of signature `current` differs from the `stored` one, in
    words; empty when they are the same (the sums to round-off)."""
    def size(s):
        return f"{int(s[0])} nodes and {int(s[1])} cells"
    if stored is None or len(stored) != 3:
        return "written for an unknown mesh"
    if stored[0] != current[0] or stored[1] != current[1]:
        return f"written for {size(stored)}, this mesh has {size(current)}"
    if abs(stored[2] - current[2]) > 1e-12 * max(abs(stored[2]), abs(current[2])):
        return "the same numbers of nodes and cells, but the nodes moved"
    return ""
