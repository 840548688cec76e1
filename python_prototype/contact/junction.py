"""Where faults cross or end on one another (cpp/contact/junction.h;
theory.md, "Faults where they meet"): the pairs around the point (a line in
3D) form a cycle, their jumps summing to zero, so they share one block of
the change of variables over all the pieces' nodes, each pair's normal jump
nu.[u] in a row of its own (junction_change_of_variables). A junction is a
connected piece of the graph whose edges are every fault's node pairs, when
it holds more than one pair."""
import dataclasses

import numpy as np
from mpi4py import MPI

from .change_of_variables import JunctionPair, junction_change_of_variables


@dataclasses.dataclass
class Junctions:
    """The faults' junctions: each one's nodes (input indices, one per
    piece around it, sorted), its pairs (fault, pair index), which of its
    nodes' displacement components are prescribed (node by node, d each),
    and of each pair at a junction its junction and the row of its + node
    that carries its constraint (the next free component of that node that
    is not prescribed, in the faults' order; d when none is left)."""
    nodes: list
    pairs: list
    prescribed: list
    of_pair: dict  # (fault, pair) -> (junction, row)


def _root(parent, v):
    """The representative of node v in a union-find forest."""
    while parent[v] != v:
        parent[v] = parent[parent[v]]
        v = parent[v]
    return v


def _connected_pairs(domain):
    """The pairs of every connected piece of the pairs' graph, by its root."""
    parent = {}
    for name in sorted(domain.faults):
        for plus, minus in domain.faults[name].pairs.tolist():
            parent.setdefault(plus, plus), parent.setdefault(minus, minus)
            parent[_root(parent, plus)] = _root(parent, minus)
    by_root = {}
    for name in sorted(domain.faults):
        for k, (plus, _) in enumerate(domain.faults[name].pairs.tolist()):
            by_root.setdefault(_root(parent, plus), []).append((name, k))
    return by_root


def _gather_prescribed(j, nodes, prescribed, d, comm):
    """Each junction's prescribed flags, from the ranks that hold its nodes."""
    flags = np.zeros(sum(d * len(around) for around in j.nodes), dtype=np.int32)
    k = 0
    for around in j.nodes:
        for v in around:
            node = nodes.local.get(v)
            if node is not None:
                flags[k:k + d] = prescribed[d * node:d * node + d]
            k += d
    comm.Allreduce(MPI.IN_PLACE, flags, op=MPI.MAX)
    k = 0
    for around in j.nodes:
        j.prescribed.append(flags[k:k + d * len(around)].astype(bool))
        k += d * len(around)


def _assign_rows(j, domain, d):
    """Each pair's row: the next free component of its + node not prescribed."""
    for i, around in enumerate(j.nodes):
        taken = j.prescribed[i].copy()
        for name, k in j.pairs[i]:
            first = d * around.index(int(domain.faults[name].pairs[k][0]))
            row = 0
            while row < d and taken[first + row]:
                row += 1
            if row < d:
                taken[first + row] = True
            j.of_pair[(name, k)] = (i, row)


def _junction_pairs(domain, j, i):
    """The pairs of junction i as its block sees them."""
    around = j.nodes[i]
    return [JunctionPair(around.index(int(domain.faults[name].pairs[k][0])),
                         around.index(int(domain.faults[name].pairs[k][1])), j.of_pair[(name, k)][1],
                         -np.asarray(domain.faults[name].normals[k])) for name, k in j.pairs[i]]


def fault_junctions(domain, nodes, prescribed):
    """The junctions of the domain's faults; `prescribed` flags the local
    DOFs of V (ghosts too) that a displacement condition prescribes
    (collective)."""
    j = Junctions([], [], [], {})
    for _, pairs in sorted(_connected_pairs(domain).items()):
        if len(pairs) > 1:
            around = set()
            for name, k in pairs:
                around |= set(domain.faults[name].pairs[k].tolist())
            j.nodes.append(sorted(around))
            j.pairs.append(pairs)
    _gather_prescribed(j, nodes, prescribed, domain.dim, domain.mesh.comm)
    _assign_rows(j, domain, domain.dim)
    return j


def junction_problem(domain, j, i):
    """What makes junction i impossible to pose, "" when nothing does: a
    piece on the + side of more faces than it has free components, a face
    not perpendicular to a prescribed component of its nodes, or faces
    meeting parallel (constraints that are not independent)."""
    pairs, d = _junction_pairs(domain, j, i), domain.dim
    for p in pairs:
        held = j.prescribed[i][d * p.plus:d * p.plus + d] | j.prescribed[i][d * p.minus:d * p.minus + d]
        if np.any((np.abs(p.normal[:d]) > 1e-12) & held):
            return ("a displacement component prescribed there is not perpendicular to the faults, which their "
                    "contact would mix with a free one (end the faults inside the body, or hold only components "
                    "along them)")
    if any(p.row >= d for p in pairs):
        return ("a piece between the faults is on the + side of more of their faces than it has free "
                "displacement components (orient the faults by their normals so that no piece is)")
    if junction_change_of_variables(pairs, len(j.nodes[i]), d, j.prescribed[i]) is None:
        return "the faults' faces there are parallel, so their contact constraints are not independent"
    return ""


def junction_block(domain, nodes, j, i):
    """The block of T at junction i in V's numbering (junction_problem
    empty): (the global unrolled DOFs of V it mixes, its matrix)."""
    d = domain.dim
    B = junction_change_of_variables(_junction_pairs(domain, j, i), len(j.nodes[i]), d, j.prescribed[i])
    return np.array([d * nodes.global_[v] + c for v in j.nodes[i] for c in range(d)], dtype=np.int64), B
