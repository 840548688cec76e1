"""The contact pair of a fault: each node on its + face against its twin on
the - face (theory.md, "Faults"; cpp/contact/fault_pair.h). With n the
fault's unit normal into the + side and g0 its initial aperture, the faces
may open but not overlap: [u].n + g0 >= 0, [u] = u+ - u-, a Signorini
constraint on the jump, nu.[u] <= g0 with nu = -n. The change of variables
of the pair (change_of_variables.py, pair_change_of_variables) makes nu.[u]
one unknown, in the + node's first row, bounded by g0; the VI solver treats
it as a node on a rigid foundation, its multiplier the contact traction on
the faces. Where faults cross or end on one another (a junction) the pairs
there share one block, each pair's nu.[u] in a row of its + node
(junction_change_of_variables)."""
import dataclasses

import numpy as np
from dolfinx import fem

from ..assembly.fault_aperture import FaultNodes, fault_nodes
from ..assembly.node_coordinates import node_coordinates
from ..scene.input import nonnegative_problem, point_text
from .change_of_variables import node_change_of_variables, pair_change_of_variables
from .contact_law import contact_law, frictionless
from .contact_set import lumped_measure, prescribed_dofs
from .junction import Junctions, fault_junctions, junction_block, junction_problem


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
    domain, the coordinates of V's nodes, its prescribed DOFs, where the
    fault nodes are, the nodes (local) that a foundation's constraint
    holds, and the faults' junctions."""
    file: str
    domain: object
    coordinates: np.ndarray
    prescribed: np.ndarray
    nodes: FaultNodes
    on_foundation: set
    junctions: Junctions


def _foundation_nodes(c):
    """The local nodes of this rank's foundation constraints (those in c so far)."""
    return {int(dof) // c.dim for dof, node in zip(c.dofs, c.pair_node) if node < 0}


def _push_constraint(c, face, k, first, gap_frame, frictional):
    """Appends constraint k of `face` to c: its row `first` (of the + node),
    gap and frame R, and whether friction acts on it."""
    node = first - first % c.dim
    c.dofs.append(first)
    c.sign.append(1)
    c.gap.append(gap_frame[0])
    c.lumped.append(face.lumped[node])
    c.normal.append(face.fault.normals[k])
    c.boundary.append(face.boundary)
    c.pair_node.append(int(face.fault.pairs[k][0]))
    c.pair_frame.append(gap_frame[1])
    c.frictional.append(frictional)
    c.output_dofs.append(face.output_dof[node])
    c.junction_nodes.append((-1, -1))


def _add_junction_pair(c, context, face, k, gap_frame):
    """The constraint of pair k where it meets other faults' pairs: the next
    free row of its + node (_fault_junctions), frictionless, its slip
    measured on u; the first pair of its junction brings the junction's
    block."""
    junction, row = context.junctions.of_pair[(face.name, k)]
    plus, minus = face.fault.pairs[k].tolist()
    first = c.dim * context.nodes.local[plus]
    if context.junctions.pairs[junction][0] == (face.name, k):
        c.blocks.append(junction_block(context.domain, context.nodes, context.junctions, junction))
    _push_constraint(c, face, k, first + row, gap_frame, False)
    c.junction_nodes[-1] = (context.nodes.global_[plus], context.nodes.global_[minus])


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
    if (face.name, k) in context.junctions.of_pair:
        if not error:
            _add_junction_pair(c, context, face, k, (g, R))
        return
    dofs = [bs * context.nodes.global_[p] + i for p in (plus, minus) for i in range(d)]
    c.blocks.append((np.array(dofs, dtype=np.int64), pair_change_of_variables(R, d)))
    # A pair with a prescribed component is held there: frictionless.
    _push_constraint(c, face, k, first, (g, R), not frictionless(c.laws[face.boundary]) and not any(held))


def _junctions_problem(context):
    """The first problem of the junctions at a node this rank holds
    (junction_problem), naming two of the faults and the point."""
    j = context.junctions
    for i, around in enumerate(j.nodes):
        problem = junction_problem(context.domain, j, i)
        held = [v for v in around if v in context.nodes.local]
        if not problem or not held:
            continue
        fault = j.pairs[i][0][0]
        other = next(name for name, _ in j.pairs[i] if name != fault)
        x = context.coordinates[context.nodes.local[held[0]]]
        return (f"{context.file}: fault.{fault}: at {point_text(x, context.domain.dim)} it meets fault {other}: "
                f"{problem}")
    return ""


def add_fault_pairs(scene, domain, F, V, c, error):
    """Adds the constraints of every fault pair whose + node this rank owns
    to the ContactSet c, with the pair's block of the change of variables;
    the first bad input (a gap below 0, a normal that mixes a prescribed
    displacement component, a junction that cannot be posed or is held by
    a prescribed displacement) goes into the list `error`, naming its key
    (collective)."""
    if not domain.faults:
        return
    nodes, prescribed = fault_nodes(domain, V), prescribed_dofs(scene, domain, V)
    context = _PairContext(scene.file, domain, node_coordinates(V), prescribed, nodes,
                           _foundation_nodes(c), fault_junctions(domain, nodes, prescribed))
    d = domain.dim
    problem = _junctions_problem(context)
    if problem and not error:
        error.append(problem)
    c.all_junction_nodes = [context.nodes.global_[v] for around in context.junctions.nodes for v in around]
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
