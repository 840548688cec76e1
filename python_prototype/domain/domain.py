"""The domain of a run (cpp/domain/domain.h): its mesh, the facets of its
named boundaries, its faults after the split and the material region of
each cell, as create_domain.py builds it from a scene; the facet markers
the forms integrate on, and the input index of each vertex."""
import dataclasses

import numpy as np
from dolfinx import mesh as dmesh

from .fault_cells import FaultCells


BOUNDARY_MARKER = 1  # forms/biot.py integrates ds(1)


@dataclasses.dataclass
class Fault:
    """A fault after the mesh was split along it (faults.py): the facets of
    its two faces, exterior facets of the split mesh (sorted local indices),
    and its node pairs, the same on every rank: per pair the input indices
    (mesh.geometry.input_global_indices) of its node on the + side and on
    the - side, (P, 2), and the fault's unit normal there, pointing into
    the + side (the mean of its facets'), (P, 3); and its cells for the
    fault's own flow (fault_cells.py)."""
    plus_facets: np.ndarray
    minus_facets: np.ndarray
    pairs: np.ndarray
    normals: np.ndarray
    cells: FaultCells


class Domain:
    def __init__(self, mesh, boundaries, regions, faults=None):
        self.mesh = mesh
        self.boundaries = boundaries  # name -> sorted local exterior facet indices
        self.regions = regions        # the material region of each cell (CellRegions)
        self.faults = faults or {}    # name -> Fault ([fault.NAME], split), in the order of scene.faults
        self.dim = mesh.topology.dim

    def marker(self, name=None, facets=None):
        """Facet tags with the marker of forms/biot.py on one boundary (or on
        the given facets), for the ds(1) integrals of that boundary."""
        facets = np.asarray(self.boundaries[name] if facets is None else facets, dtype=np.int32)
        return dmesh.meshtags(self.mesh, self.dim - 1, facets,
                              np.full(len(facets), BOUNDARY_MARKER, dtype=np.int32))

    def fault_faces(self, name):
        """The same on both faces of the fault `name`."""
        fault = self.faults[name]
        return self.marker(facets=np.unique(np.concatenate([fault.plus_facets, fault.minus_facets])))


def vertex_input_indices(mesh):
    """The input index of every local vertex (owned and ghost): vertex k of
    a cell is the cell's geometry node k on a P1 mesh."""
    tdim = mesh.topology.dim
    mesh.topology.create_connectivity(tdim, 0)
    vertex_map = mesh.topology.index_map(0)
    result = np.empty(vertex_map.size_local + vertex_map.num_ghosts, dtype=np.int64)
    input_index = np.asarray(mesh.geometry.input_global_indices, dtype=np.int64)
    result[mesh.topology.connectivity(tdim, 0).array] = input_index[mesh.geometry.dofmap.array]
    return result


def pore_pressure_faces(scene, domain):
    """The facets of the faces loaded by the pore pressure
    (boundary.NAME.pore_pressure_load, and both faces of a fault with
    fault.NAME.pore_pressure_load) with the marker of forms/biot.py; None
    when the scene has none (cpp/domain/domain.h). Whether there are any is
    the same on every rank, whatever facets each holds."""
    facets = [domain.boundaries[name] for name, b in sorted(scene.boundaries.items()) if b.pore_pressure_load]
    for name, f in scene.faults.items():
        if f.pore_pressure_load:
            facets += [domain.faults[name].plus_facets, domain.faults[name].minus_facets]
    if not facets:
        return None
    return domain.marker(facets=np.unique(np.concatenate(facets)))
