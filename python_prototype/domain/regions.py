"""Material regions: which cells each [region.NAME] of a scene holds
(cpp/domain/regions.cpp)."""
import numpy as np
from dolfinx import mesh as dmesh

from ..scene.scene import SceneError, agree_on_error


class CellRegions:
    """The region of every cell: an index into the scene's regions (in the
    order of their names), or -1 for the top-level material."""

    def __init__(self, names, region, counts, outside):
        self.names = names        # the scene's regions, in name order
        self.region = region      # per local cell (owned and ghost)
        self.counts = counts      # global number of cells of each region
        self.outside = outside    # global number of cells in no region


def _overlap(scene, name, other):
    return f"{scene.file}: region.{name}: claims cells of region.{other} too (a cell belongs to one region at most)"


def regions_of_groups(scene, num_cells, groups):
    """Rank 0: the region of each input cell of a gmsh file from the cells of
    each named physical group of cells (`groups`: name -> input cell indices)."""
    names = sorted(scene.regions)
    region = np.full(num_cells, -1, dtype=np.int32)
    for index, name in enumerate(names):
        if scene.regions[name].where is not None:
            continue
        if name not in groups:
            known = ", ".join(sorted(groups)) or "none"
            raise SceneError(f"{scene.file}: region.{name}: no physical group of cells of that name in "
                             f"{scene.mesh.file} (it has {known}; or select the cells with where = \"expression\")")
        cells = np.asarray(groups[name], dtype=np.int64)
        taken = region[cells]
        clash = taken[(taken >= 0) & (taken != index)]
        if len(clash):
            raise SceneError(_overlap(scene, name, names[clash[0]]))
        region[cells] = index
    return region


def _select_by_midpoint(scene, mesh, r):
    """The regions given by `where`; the first overlap on this rank, or ''."""
    d = mesh.topology.dim
    x = dmesh.compute_midpoints(mesh, d, np.arange(len(r.region), dtype=np.int32))
    for index, name in enumerate(r.names):
        where = scene.regions[name].where
        if where is None:
            continue
        selected = np.flatnonzero(where(x[:, 0], x[:, 1], x[:, 2], 0.0) != 0.0)
        taken = r.region[selected]
        clash = taken[(taken >= 0) & (taken != index)]
        if len(clash):
            return _overlap(scene, name, r.names[clash[0]])
        r.region[selected] = index
    return ""


def locate_regions(scene, mesh, input_region):
    """The regions of `scene` on `mesh` (cpp/domain/regions.h): `input_region`
    holds on rank 0 the region of each gmsh input cell (None for a built-in
    mesh); the others are the cells whose midpoint satisfies `where`."""
    d = mesh.topology.dim
    cell_map = mesh.topology.index_map(d)
    owned = cell_map.size_local
    names = sorted(scene.regions)
    r = CellRegions(names, np.full(owned + cell_map.num_ghosts, -1, dtype=np.int32), [], 0)
    comm = mesh.comm
    if any(region.where is None for region in scene.regions.values()):
        everywhere = comm.bcast(input_region, root=0)
        original = np.asarray(mesh.topology.original_cell_index, dtype=np.int64)
        n = min(len(original), len(r.region))
        r.region[:n] = everywhere[original[:n]]
    if names:
        agree_on_error(_select_by_midpoint(scene, mesh, r), comm)
    local = np.bincount(r.region[:owned] + 1, minlength=len(names) + 1).astype(np.int64)
    total = comm.allreduce(local)
    r.outside, r.counts = int(total[0]), [int(c) for c in total[1:]]
    for name, count in zip(names, r.counts):
        if count == 0:
            raise SceneError(f"{scene.file}: region.{name}: holds no cell"
                             + (" (no cell midpoint satisfies where)" if scene.regions[name].where else ""))
    return r
