"""The input mesh's topology before the split along faults (faults.py): the
cells of each facet and of each node, in the input numbering, on rank 0
before dolfinx distributes the mesh (cpp/domain/mesh_topology.h)."""
import dataclasses

import numpy as np

FacetKey = tuple  # a facet by its sorted nodes


def facet_key(nodes):
    """A facet by its sorted nodes: the same facet seen from either of its
    cells or from a group has one key."""
    return tuple(sorted(int(v) for v in nodes))


@dataclasses.dataclass
class InputTopology:
    """The input mesh's topology before the split: its cells as read (every
    look-up uses the input numbering while the split renumbers the mesh's
    cells), the cells of each facet and the cells of each node (ascending)."""
    d: int
    cells: np.ndarray
    facet_cells: dict
    node_cells: list


def topology_of(d, cells, nodes):
    """The topology of the d-simplices `cells` (d + 1 node indices each)
    over `nodes` nodes."""
    t = InputTopology(d, np.array(cells, dtype=np.int64).reshape(-1, d + 1), {}, [[] for _ in range(nodes)])
    for c, cell in enumerate(t.cells.tolist()):
        for j, v in enumerate(cell):
            # The facet opposite node j.
            t.facet_cells.setdefault(facet_key(cell[:j] + cell[j + 1:]), []).append(c)
            t.node_cells[v].append(c)
    return t


def cells_of(t, key):
    """The cells that have the facet `key` (ascending): two inside the body,
    one on the outer boundary."""
    return t.facet_cells.get(key, [])


def local_index(t, cell, node):
    """The position of `node` in the input cell `cell`."""
    return int(np.flatnonzero(t.cells[cell] == node)[0])
