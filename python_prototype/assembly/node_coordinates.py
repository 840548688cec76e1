"""The coordinates of the nodes of a P1 space, read from the mesh geometry
(cpp/assembly/node_coordinates.h): V.tabulate_dof_coordinates() pushes the
reference points forward with basis values exact only to round-off (a node
at x = 0 at 5e-18 under an optimised BLAS); a P1 node is a mesh node."""
import numpy as np


def on_mesh_nodes(V):
    """Whether V is P1 on the mesh's nodes: as many nodes per cell as the
    cell has geometry nodes (an affine mesh's vertices)."""
    geometry = V.mesh.geometry.dofmap
    return geometry.num_nodes == 0 or len(V.dofmap.cell_dofs(0)) == len(geometry.links(0))


def node_coordinates(V):
    """The coordinates of the nodes (blocks) of the P1 space V, owned and
    ghost, an (n, 3) array in V's node numbering: the layout of
    V.tabulate_dof_coordinates()."""
    geometry = V.mesh.geometry
    cells = geometry.dofmap.num_nodes
    dofs = V.dofmap.list.array.reshape(cells, -1)
    geometry_nodes = geometry.dofmap.array.reshape(cells, -1)
    if dofs.shape != geometry_nodes.shape:
        raise RuntimeError("node_coordinates: the space is not P1 on the mesh's nodes")
    index_map = V.dofmap.index_map
    coordinates = np.zeros((index_map.size_local + index_map.num_ghosts, 3))
    coordinates[dofs.ravel()] = geometry.x[geometry_nodes.ravel()]  # vertex i of a cell is the i-th of each
    return coordinates
