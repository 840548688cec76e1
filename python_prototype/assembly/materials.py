"""The material coefficients of the forms, cell by cell: the scene's
top-level values in cells in no region, a region's own in its cells
(cpp/assembly/materials.h)."""
import numpy as np
from dolfinx import fem

from ..scene.scene import agree_on_error
from .parameters import derive_parameters, resistivity

SCALARS = (("G", "G"), ("lmbda", "lmbda"), ("alpha", "alpha"), ("storage", "storage"), ("L", "L"))


class Materials:
    """The parameters of the top-level material and of each region, and over
    the materials that hold cells the largest gamma and L and the smallest S
    and S + L. The DG0 coefficients G, lmbda, alpha, storage, L and
    resistivity live in the forms (Forms), set by make_materials."""

    def __init__(self, top, regions, cells):
        self.top, self.regions = top, regions
        used = ([top] if cells.outside > 0 else []) + regions
        self.gamma = max(p.gamma for p in used)
        self.max_L = max(p.L for p in used)
        self.min_storage = min(p.storage for p in used)
        self.min_stabilised_storage = min(p.storage + p.L for p in used)

    def without_stabilisation(self, F, into):
        """Sets the coefficients of F into the forms `into` with L = 0 (the
        second pass of "multirate-two-pass"); the materials of that pass."""
        for name, _ in SCALARS:
            into[name].x.array[:] = 0.0 if name == "L" else F[name].x.array
        into["resistivity"].x.array[:] = F["resistivity"].x.array
        m = Materials.__new__(Materials)
        m.__dict__.update(self.__dict__)
        m.max_L, m.min_stabilised_storage = 0.0, self.min_storage
        return m


def _per_cell(f, components, value):
    """Interpolates into a DG0 function a value per cell: value(cells, x)
    returns the components at the midpoints x of the cells (dolfinx
    interpolates into DG0 at one point per cell, the cells in their local order)."""
    def values(x):
        v = value(np.arange(x.shape[1]), x)
        return v if components > 1 else v.reshape(-1)
    f.interpolate(values)


def _set_resistivity(R, scene, cells, d):
    """mu_f K^-1 cell by cell; the first permeability that is not positive on this rank, or ''."""
    flows = [scene.flow] + [scene.regions[name].flow for name in cells.names]
    error = []

    def value(c, x):
        v = np.zeros((d * d, x.shape[1]))
        region = cells.region[c]
        for r in np.unique(region):
            at = np.flatnonzero(region == r)
            values, bad = resistivity(flows[r + 1], d, x[:, at])
            v[:, at] = values
            if len(bad) and not error:
                p = x[:, at[bad[0]]]
                key = "flow" if r < 0 else "region." + cells.names[r]
                where = ", ".join(f"{c:g}" for c in p[:d])
                error.append(f"{scene.file}: {key}.permeability: must be positive at ({where})")
        return v
    _per_cell(R, d * d, value)
    return error[0] if error else ""


def make_materials(scene, domain, F):
    """The materials of a scene on its domain, set into F's coefficients; a
    permeability that is not positive is a SceneError naming its key."""
    cells = domain.regions
    top = derive_parameters(scene)
    regions = [derive_parameters(scene, scene.regions[name]) for name in cells.names]
    every = [top] + regions
    for name, member in SCALARS:
        table = np.array([getattr(p, member) for p in every])
        _per_cell(F[name], 1, lambda c, x, table=table: table[cells.region[c] + 1])
    if scene.flow:
        agree_on_error(_set_resistivity(F["resistivity"], scene, cells, domain.dim), domain.mesh.comm)
    return Materials(top, regions, cells)


def on(F, name, Q):
    """The values of coefficient `name` in the DOF order of the DG0 space Q."""
    f = fem.Function(Q)
    f.interpolate(F[name])
    return f.x.array.copy()
