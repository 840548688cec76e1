"""The contact pair of a face against a rigid foundation (alg. "Mechanics
with frictionless Signorini contact"; cpp/contact/foundation_pair.h): each
node of a contact boundary and each foundation it touches, u.nu_F <= g_a. A
node on two boundaries with the same normal holds one constraint (the
smaller gap), with different normals two (the apex of a groove); normals
along coordinate axes bound a component of u itself, others go through the
node's change of variables (change_of_variables.py)."""
from collections import namedtuple

import numpy as np
from dolfinx import fem

from ..assembly.linear_algebra import owned
from ..assembly.node_coordinates import node_coordinates
from ..scene.input import nonnegative_problem, point_text
from .change_of_variables import coordinate_axis, node_change_of_variables
from .contact_law import contact_law, frictionless
from .contact_set import lumped_measure, prescribed_dofs

# A contact node: its first DOF in V, its candidate constraints (one per
# foundation that holds it) and its coordinates.
_ContactNode = namedtuple("_ContactNode", "first candidates x")


def _unit_normal(contact, x, d):
    """The foundation's normal at x, normalised; None where it is zero or
    not finite."""
    n = np.zeros(3)
    n[:d] = [float(c(x[0], x[1], x[2], 0.0)) for c in contact.normal]
    length = np.sqrt(np.dot(n, n))
    return n / length if length > 0 and np.isfinite(length) else None


def _gather_candidates(scene, domain, F, V, c, error):
    """The constraints of each contact boundary at each owned node, by node
    in the order first met (boundaries in the scene's order, each
    boundary's DOFs in dolfinx's): the order of the constraints."""
    d, bs, n_owned = domain.dim, V.dofmap.index_map_bs, owned(V)
    coords, V0, nodes = node_coordinates(V), V.sub(0), {}
    for name, b in scene.boundaries.items():
        if not b.contact:
            continue
        boundary = len(c.boundaries)
        c.boundaries.append(name)
        c.faults.append(False)
        c.laws.append(contact_law(b.contact.friction))
        lumped = lumped_measure(domain, F, V, domain.boundaries[name])
        dofs, collapsed = fem.locate_dofs_topological((V0, c.output_space), d - 1, domain.boundaries[name])
        for dof, out in zip(dofs, collapsed):
            if dof >= n_owned:
                continue
            x = coords[dof // bs]
            g = float(b.contact.gap(x[0], x[1], x[2], 0.0))
            n = _unit_normal(b.contact, x, d)
            problem = nonnegative_problem(g)
            if problem and not error:
                error.append(f"{scene.file}: boundary.{name}.contact.gap: {problem} at {point_text(x, d)}")
            if n is None and not error:
                error.append(f"{scene.file}: boundary.{name}.contact.normal: zero or not finite at {point_text(x, d)}")
            if n is not None:
                nodes.setdefault(int(dof), []).append(
                    dict(normal=n, gap=g, lumped=lumped[dof], output_dof=int(out), boundary=boundary))
    return nodes


def _merged(candidates):
    """A node's candidates merged: the same normal from two boundaries is one
    constraint, with the smaller gap and the measures added."""
    merged = []
    for k in candidates:
        same = [m for m in merged if np.max(np.abs(m["normal"] - k["normal"])) < 1e-12]
        if same:
            same[0]["gap"] = min(same[0]["gap"], k["gap"])
            same[0]["lumped"] += k["lumped"]
        else:
            merged.append(dict(k))
    return merged


def _frictional_node(c, node, merged, prescribed, report):
    """Whether friction acts at a node with the merged candidates `merged`
    (cpp/contact/foundation_pair.cpp). Friction acts on the tangential
    components of a node's change of variables (rows 1..d-1 of T): a
    frictional node always has one, and only one foundation (two would leave
    fewer tangents than friction needs: the first bad input, naming the
    frictional boundary, goes into the error). A node with a prescribed
    component (on a symmetry plane, say) is held there by it: its contact
    stays frictionless (docs/user-guide.md). `report` is (file, error)."""
    file, error = report
    if np.any(prescribed[node.first:node.first + c.dim]):
        return False
    law = next((m for m in merged if not frictionless(c.laws[m["boundary"]])), None)
    if law is None:
        return False
    if len(merged) > 1 and not error:
        error.append(f"{file}: boundary.{c.boundaries[law['boundary']]}.contact.friction: at "
                     f"{point_text(node.x, c.dim)} two foundations meet, where friction is not supported yet")
    return True


def _add_node(c, node, prescribed, file, error):
    """One node's merged candidates entered into c as bounds on its own
    components (normals along coordinate axes) or on the components of its
    change of variables. The first bad input goes into `error`, with its
    key in `file`."""
    first, x, d = node.first, node.x, c.dim
    merged = _merged(node.candidates)
    axes = [coordinate_axis(m["normal"], d) for m in merged]
    frictional = _frictional_node(c, node, merged, prescribed, (file, error))
    on_axes = not frictional and all(a is not None for a in axes) and len({a[0] for a in axes}) == len(merged)
    T = None
    if not on_axes:
        normals = [m["normal"] for m in merged]
        T = node_change_of_variables(normals, d, [False] * 3)
        key = f"{file}: boundary.{c.boundaries[merged[0]['boundary']]}.contact.normal: at {point_text(x, d)}"
        if T is None and not error:
            error.append(key + " the normals of the foundations that meet there are not independent")
        elif T is not None and node_change_of_variables(normals, d, prescribed[first:first + d]) is None \
                and not error:
            error.append(key + " the normal is not perpendicular to a prescribed displacement component of the node")
        if T is None:
            return
        c.blocks.append((c.dof_offset + first + np.arange(d), T))
    for j, m in enumerate(merged):
        c.dofs.append(first + (axes[j][0] if on_axes else j))
        c.sign.append(axes[j][1] if on_axes else 1)
        c.gap.append(m["gap"])
        c.lumped.append(m["lumped"])
        c.normal.append(m["normal"])
        c.boundary.append(m["boundary"])
        c.pair_node.append(-1)
        c.junction_nodes.append((-1, -1))
        c.pair_frame.append(T)
        c.frictional.append(frictional)
        c.output_dofs.append(m["output_dof"])


def add_foundation_pairs(scene, domain, F, V, c, error):
    """Adds the constraints of the scene's contact boundaries at the nodes
    this rank owns to the ContactSet c; the first bad input (a gap below 0,
    a normal that is zero or not finite at a node, normals at a node that
    are not independent, or one that is not perpendicular to a prescribed
    displacement component of its node) goes into the list `error`, naming
    its key."""
    nodes = _gather_candidates(scene, domain, F, V, c, error)
    prescribed = prescribed_dofs(scene, domain, V)
    coords, bs = node_coordinates(V), V.dofmap.index_map_bs
    for first, candidates in nodes.items():
        _add_node(c, _ContactNode(first, candidates, coords[first // bs]), prescribed, scene.file, error)
