"""Where the wells are (cpp/domain/wells.cpp): the owned cells each
[well.NAME] lies in (a point in 2D, a vertical segment in 3D) and the share
of its rate each takes, a well outside the mesh refused; and where a well
is, in words. The flow's sources (assembly/wells.py) and the scene's checks
(mesh_checks.py) use them."""
import numpy as np

from ..scene.scene import SceneError


def _well_weights(v, w, d, tolerance=1e-10):
    """Per cell (vertices v: cells x (d+1) x 3): 1 if the point (2D) lies in
    the triangle (boundary included), or the length of the vertical segment
    (3D) inside the tetrahedron, from the barycentric coordinates along it."""
    px, py = w.position
    if d == 2:
        e1, e2 = v[:, 1] - v[:, 0], v[:, 2] - v[:, 0]
        det = e1[:, 0] * e2[:, 1] - e2[:, 0] * e1[:, 1]
        l1 = ((px - v[:, 0, 0]) * e2[:, 1] - e2[:, 0] * (py - v[:, 0, 1])) / det
        l2 = (e1[:, 0] * (py - v[:, 0, 1]) - (px - v[:, 0, 0]) * e1[:, 1]) / det
        return ((l1 >= -tolerance) & (l2 >= -tolerance) & (1 - l1 - l2 >= -tolerance)).astype(float)
    # lambda_i(s) = a_i + b_i s for the point (px, py, s), i = 1..3, from the
    # inverse of T = [v1 - v0, v2 - v0, v3 - v0]; lambda_0 = 1 - sum.
    inverse = np.linalg.inv(np.stack([v[:, 1] - v[:, 0], v[:, 2] - v[:, 0], v[:, 3] - v[:, 0]], axis=2))
    p0 = np.array([px, py, 0.0]) - v[:, 0]
    a = np.einsum("cij,cj->ci", inverse, p0)
    b = inverse[:, :, 2]
    a = np.concatenate([1 - a.sum(axis=1, keepdims=True), a], axis=1)
    b = np.concatenate([-b.sum(axis=1, keepdims=True), b], axis=1)
    flat = np.abs(b) < 1e-14 * (1 + np.abs(a))
    with np.errstate(divide="ignore", invalid="ignore"):
        bound = -(a + tolerance) / b
    low = np.max(np.where(~flat & (b > 0), bound, w.bottom), axis=1, initial=w.bottom)
    high = np.min(np.where(~flat & (b < 0), bound, w.top), axis=1, initial=w.top)
    return np.where(np.any(flat & (a < -tolerance), axis=1), 0.0, np.maximum(0.0, high - low))


def well_place(w, d):
    """Where well `w` is, in words: "(x, y)", and in 3D " from z = bottom to
    top"."""
    return f"({w.position[0]:g}, {w.position[1]:g})" + (f" from z = {w.bottom:g} to {w.top:g}" if d == 3 else "")


def locate_well(domain, w, key):
    """The owned cells of well `w` and the share of its rate each takes (a
    point on a shared edge or vertex split equally among its cells; a
    segment by its length in each cell); SceneError naming `key` when it is
    not in the mesh or its segment leaves it (collective)."""
    mesh, d = domain.mesh, domain.dim
    owned = mesh.topology.index_map(d).size_local
    nodes = mesh.geometry.dofmap.array.reshape(-1, d + 1)[:owned]
    weights = _well_weights(mesh.geometry.x[nodes], w, d) if owned else np.zeros(0)
    cells = np.flatnonzero(weights > 0).astype(np.int32)
    total = mesh.comm.allreduce(float(np.sum(weights[cells])))
    length = 1.0 if d == 2 else w.top - w.bottom
    if not total >= length * (1 - 1e-9):
        raise SceneError(f"{key}: the well at {well_place(w, d)} "
                         f"{'is not in the mesh' if d == 2 or total == 0 else 'leaves the mesh'}")
    return cells, weights[cells] / total
