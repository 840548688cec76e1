"""The contact pair of a fault: each node on its + face against its twin on
the - face (theory.md, "Faults"; cpp/contact/fault_pair.h). With n the
fault's unit normal into the + side and g0 its initial aperture, the faces
may open but not overlap:
    [u].n + g0 >= 0,   [u] = u+ - u-,
a Signorini constraint on the jump, nu.[u] <= g0 with nu = -n. The change of
variables of the pair (change_of_variables.py, pair_change_of_variables)
makes nu.[u] one unknown, in the + node's first row, bounded by g0; the VI
solver then treats it as it treats a node on a rigid foundation, and its
multiplier is the contact traction on the faces."""
import dataclasses

import numpy as np
from dolfinx import fem

from ..assembly.fault_aperture import FaultNodes, fault_nodes
from ..scene.input import nonnegative_problem, point_text
from .change_of_variables import node_change_of_variables, pair_change_of_variables
from .contact_law import contact_law, frictionless
from .contact_set import lumped_measure, prescribed_dofs


@dataclasses.dataclass
class _FaultFace:
    """One fault's data for its constraints: its name and index among the
    contact's boundaries, its Fault and scene entry, and per node of its +
    face the lumped measure and the node in the output space."""
    name: str
    fault: object
    boundary: int
    spec: object
    lumped: np.ndarray
    output_dof: dict  # first DOF in V -> node in c.output_space


@dataclasses.dataclass
class _PairContext:
    """What every pair's constraint reads: the scene file (for messages), the
    coordinates of V's nodes, its prescribed DOFs, where the fault nodes
    are, and the nodes (local) that a foundation's constraint holds."""
    file: str
    coordinates: np.ndarray
    prescribed: np.ndarray
    nodes: FaultNodes
    on_foundation: set


def _foundation_nodes(c):
    """The local nodes of this rank's foundation constraints (those in c so far)."""
    return {int(dof) // c.dim for dof, node in zip(c.dofs, c.pair_node) if node < 0}


def _add_pair(c, context, face, k, error):
    """The constraint of node pair k, if this rank owns its + node."""
    d = bs = c.dim
    plus, minus = face.fault.pairs[k].tolist()
    n = face.fault.normals[k]
    node = context.nodes.local.get(plus)
    if node is None or bs * node not in face.output_dof:  # not owned here
        return
    first, x = bs * node, context.coordinates[node]
    g = float(face.spec.gap(x[0], x[1], x[2], 0.0))
    key = f"{context.file}: fault.{face.name}"
    problem = nonnegative_problem(g)
    if problem and not error:
        error.append(f"{key}.gap: {problem} at {point_text(x, d)}")
    # the pair's change of variables (jump, - face) would leave the + node's
    # foundation constraint no DOF of its own
    if node in context.on_foundation and not error:
        error.append(f"{key}: at {point_text(x, d)} it reaches a contact boundary, where a fault is not supported "
                     "yet (end it inside the body)")
    held = context.prescribed[first:first + d]
    R = node_change_of_variables([-n], d, held)
    if R is None:
        if not error:
            error.append(f"{key}.normal: at {point_text(x, d)} the fault is not perpendicular to a prescribed "
                         "displacement component of the node")
        return
    dofs = [bs * context.nodes.global_[p] + i for p in (plus, minus) for i in range(d)]
    c.blocks.append((np.array(dofs, dtype=np.int64), pair_change_of_variables(R, d)))
    c.dofs.append(first)
    c.sign.append(1)
    c.gap.append(g)
    c.lumped.append(face.lumped[first])
    c.normal.append(n)
    c.boundary.append(face.boundary)
    c.pair_node.append(plus)
    c.pair_frame.append(R)
    # A pair with a prescribed component is held there: frictionless.
    c.frictional.append(not frictionless(c.laws[face.boundary]) and not any(held))
    c.output_dofs.append(face.output_dof[first])


def add_fault_pairs(scene, domain, F, V, c, error):
    """Adds the constraints of every fault pair whose + node this rank owns
    to the ContactSet c, with the pair's block of the change of variables;
    the first bad input (a gap below 0, a normal that mixes a prescribed
    displacement component) goes into the list `error`, naming its key
    (collective)."""
    if not domain.faults:
        return
    context = _PairContext(scene.file, V.tabulate_dof_coordinates(), prescribed_dofs(scene, domain, V),
                           fault_nodes(domain, V), _foundation_nodes(c))
    d = domain.dim
    n_owned = d * V.dofmap.index_map.size_local
    for name, fault in domain.faults.items():
        face = _FaultFace(name, fault, len(c.boundaries), scene.faults[name],
                          lumped_measure(domain, F, V, fault.plus_facets), {})
        c.boundaries.append(name)
        c.faults.append(True)
        c.laws.append(contact_law(scene.faults[name].friction))
        dofs, collapsed = fem.locate_dofs_topological((V.sub(0), c.output_space), d - 1, fault.plus_facets)
        face.output_dof = {int(dof): int(out) for dof, out in zip(dofs, collapsed) if dof < n_owned}
        for k in range(len(fault.pairs)):
            _add_pair(c, context, face, k, error)
