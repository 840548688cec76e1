"""Where the conduit faults' unknowns live among the ranks: each fault cell
(domain/fault_cells.py), numbered fault by fault in the scene's order, is
owned by the rank that owns its first + node, so its rows sit with the rock
they touch. Twin: cpp/assembly/fault_rows.h."""
import numpy as np
from mpi4py import MPI
from petsc4py import PETSc

from ..domain.domain import vertex_input_indices
from ..scene.input import FaultFlow


class FaultRows:
    """The conduit faults' cells as rows of a distributed system: each
    cell's owner and global row; rank r's cells, in the cells' order, are the
    rows [start_r, start_r + owned_r) (contiguous, as PETSc numbers a rank's
    rows). Arrays "of this rank's entries" hold the owned cells in that
    order."""

    def __init__(self, comm, owner):
        self.comm, self.rank, self.owner = comm, comm.rank, owner
        counts = np.bincount(owner, minlength=comm.size)
        self.offsets = np.concatenate([[0], np.cumsum(counts)[:-1]])
        self.counts = counts
        order = np.argsort(owner, kind="stable")  # by rank, each rank's in the cells' order
        self.row = np.empty(len(owner), dtype=PETSc.IntType)
        self.row[order] = np.arange(len(owner), dtype=PETSc.IntType)
        self.mine = np.flatnonzero(owner == comm.rank)

    @property
    def size(self):
        return len(self.owner)

    @property
    def owned(self):
        return len(self.mine)

    def owns(self, cell):
        return self.owner[cell] == self.rank

    def everywhere(self, owned):
        """Every cell's values from each rank's entries (collective)."""
        by_row = np.empty(self.size)
        self.comm.Allgatherv(np.ascontiguousarray(owned, dtype=float), [by_row, self.counts, self.offsets, MPI.DOUBLE])
        return by_row[self.row]

    def entries(self, values):
        """This rank's entries of `values` (a value per cell)."""
        return np.asarray(values, dtype=float)[self.mine]


def fault_rows(scene, domain):
    """The rows of the scene's conduit faults in `domain` (collective)."""
    mesh = domain.mesh
    owned = set(vertex_input_indices(mesh)[:mesh.topology.index_map(0).size_local].tolist())
    claims = []
    for name, f in sorted(scene.faults.items()):  # the order of the C++ std::map
        if f.flow == FaultFlow.conduit:
            claims += [mesh.comm.rank if int(key) in owned else -1 for key in domain.faults[name].cells.keys[:, 0]]
    owner = np.array(claims, dtype=np.int32)
    # A vertex has one owner: the largest rank claiming a cell is its only one.
    mesh.comm.Allreduce(MPI.IN_PLACE, owner, op=MPI.MAX)
    return FaultRows(mesh.comm, np.maximum(owner, 0))
