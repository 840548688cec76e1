"""The opening of the conduit faults' cells as a linear map of the
displacement, and the load of the faults' fluid pressure on their faces
(cpp/assembly/fault_aperture.h, docs/theory.md "Flow in a fault"). Per cell
k (a facet of the fault, d nodes), the mean of the nodes' openings g0 + [u].n:

    w_k = g0_k + (J u)_k,   (J u)_k = (1/d) sum_i n_k . (u(i+) - u(i-)),

n_k the cell's normal into the + side, i- the twin of node i+ on the - face
(the node itself at a tip, where the opening is 0). The fluid pressure's
load is the adjoint b += J^T (|k| p_f) (FaultAperture.add_load)."""
import dataclasses

import numpy as np
from dolfinx import fem
from petsc4py import PETSc

from ..domain.domain import vertex_input_indices
from ..scene.input import FaultFlow
from .fault_rows import fault_rows


@dataclasses.dataclass
class FaultNodes:
    """Where the faults' nodes are in a P1 space V: the local node of each
    input index this rank holds, and the global node of every fault node (a
    pair's - node may be held by another rank only)."""
    local: dict
    global_: dict


def fault_nodes(domain, V):
    """The FaultNodes of every fault's node pairs and cells in V (collective)."""
    mesh = domain.mesh
    tdim = mesh.topology.dim
    wanted = np.unique(np.concatenate([np.concatenate([f.pairs.ravel(), f.cells.keys.ravel()])
                                       for f in domain.faults.values()]))
    # Vertex k of a cell is its DOF k of a P1 space.
    vertices = vertex_input_indices(mesh)[mesh.topology.connectivity(tdim, 0).array].reshape(-1, tdim + 1)
    dofs = V.dofmap.list.array.reshape(-1, tdim + 1)
    mask = np.isin(vertices, wanted)
    local = dict(zip(vertices[mask].tolist(), dofs[mask].tolist()))
    # Every rank learns the global node of each fault node from its owner.
    index_map = V.dofmap.index_map
    mine = [(index, index_map.local_range[0] + node) for index, node in local.items() if node < index_map.size_local]
    return FaultNodes(local, dict(pair for rank in mesh.comm.allgather(mine) for pair in rank))


class FaultAperture:
    """The mean opening w = g0 + J u of each conduit fault cell, and the
    load J^T (|k| p_f) of the faults' fluid pressure. The rows of J are the
    conduit cells in ConduitFaults' numbering (fault by fault), each on its
    owner (fault_rows.py)."""

    def __init__(self, scene, domain, V):
        """V: the P1 displacement space."""
        self.comm, self.rows = domain.mesh.comm, fault_rows(scene, domain)
        d = domain.dim
        conduits = [(name, f) for name, f in sorted(scene.faults.items()) if f.flow == FaultFlow.conduit]
        self.size = self.rows.size
        nodes = fault_nodes(domain, V)
        self.J = PETSc.Mat().createAIJ(((self.rows.owned, None), (d * V.dofmap.index_map.size_local, None)),
                                       nnz=(2 * d * d, 2 * d * d), comm=self.comm)
        self.gap, self.measures, cell = [], [], 0  # cell: among every conduit's cells
        # the + nodes of every cell, d per cell (every rank)
        self.keys = np.concatenate([domain.faults[name].cells.keys for name, _ in conduits]) if conduits else None
        # every cell's fault (every rank)
        self.fault = [name for name, _ in conduits for _ in range(len(domain.faults[name].cells.measures))]
        for name, f in conduits:
            cells = domain.faults[name].cells
            for k in range(len(cells.measures)):
                cell += 1
                if not self.rows.owns(cell - 1):
                    continue
                row = self.rows.row[cell - 1]
                self.gap.append(np.mean([float(f.gap(*v, 0.0)) for v in cells.vertices[k]]))
                self.measures.append(cells.measures[k])
                for i in range(d):
                    for node, sign in ((cells.keys[k, i], 1.0), (cells.twins[k, i], -1.0)):
                        columns = [d * nodes.global_[int(node)] + j for j in range(d)]
                        self.J.setValues(row, columns, sign * cells.normals[k, :d] / d, addv=True)
        self.J.assemble()
        self.gap, self.measures = np.array(self.gap), np.array(self.measures)
        self.cells = self.J.createVecLeft()

    def opening(self, u):
        """The conduit cells' mean openings g0 + J u, every cell on every rank
        (u: a Function of V; collective)."""
        self.J.mult(u.vector, self.cells)
        return self.rows.everywhere(self.gap + self.cells.array_r)

    def cell_means(self, nodal):
        """Per conduit cell the mean of `nodal` (a dict: a value per fault and
        + node this rank knows, by the fault's name and the node's input
        index; each on one rank) over the cell's nodes that have one on its
        fault, 0 where none has; every cell on every rank (collective). Of
        the fault pairs' contact tractions, the cells' effective normal
        stress s_n."""
        values = {key: value for rank in self.comm.allgather(nodal) for key, value in rank.items()}
        means = np.zeros(self.size)
        for k, keys in enumerate(self.keys.tolist() if self.size else []):
            known = [values[(self.fault[k], node)] for node in keys if (self.fault[k], node) in values]
            means[k] = sum(known) / max(len(known), 1)
        return means

    def add_load(self, p_f, bcs, b):
        """Adds J^T (|k| p_f) to the Function b but on the Dirichlet rows of
        `bcs`; `p_f`: this rank's entries of the pressures (collective).
        The fluid pressure p_f pushes both faces apart; its work on the
        displacement is sum_k p_k |k| w_k, so its load is the adjoint of J:
        for P1 on a flat face each node takes |k|/d of the face's p_f n, the
        integral forms/biot.py's L_face_pressure takes of a given pressure."""
        self.cells.array[:] = self.measures * np.asarray(p_f)[:len(self.measures)]
        load = fem.Function(b.function_space)
        self.J.multTranspose(self.cells, load.vector)
        fem.set_bc(load.x.array, bcs, scale=0.0)
        n = b.function_space.dofmap.index_map.size_local * b.function_space.dofmap.index_map_bs
        b.x.array[:n] += load.x.array[:n]
