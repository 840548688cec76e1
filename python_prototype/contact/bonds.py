"""The bonds of the cohesive constraints (contact_law.py, "the bond"): which
break after a failed solve or an accepted step, and their names in a
checkpoint. The contact solver (contact.py) keeps them as of now
(ContactSet.bonded) and as of the last accepted step.
Twin: cpp/contact/bonds.h."""
import numpy as np

from ..solvers.solver import SolverError


class BondFailure(SolverError):
    """A contact solve that failed on every path though the bonds its
    clamped start pulled were broken: pairs the remaining bonds hold still
    have no state (pulled while closed, overlapping while open), as where a
    split's p_f, from the flow alone, passes a cohesive fault's normal
    stress along its length."""


def constraint_keys(contact_set):
    """A name of each constraint that no partition changes: the input index
    of its node (a fault pair's + node) times 4, plus its place among the
    constraints of that node (two or three foundations may meet there)."""
    P1 = contact_set.output_space
    mesh = P1.mesh
    # The P1 output space: a cell's DOF k sits on its geometry node k.
    node_input = np.zeros(P1.dofmap.index_map.size_local + P1.dofmap.index_map.num_ghosts, dtype=np.int64)
    node_input[P1.dofmap.list.array] = np.asarray(mesh.geometry.input_global_indices, dtype=np.int64)[
        mesh.geometry.dofmap.array]
    keys, seen = [], {}
    for dof in contact_set.output_dofs:
        keys.append(4 * int(node_input[dof]) + seen.get(int(dof), 0))
        seen[int(dof)] = seen.get(int(dof), 0) + 1
    return np.array(keys, dtype=np.int64)


def cohesive(contact_set):
    """Whether any contact boundary or fault of `contact_set` has a cohesion."""
    return any(law.cohesion > 0 for law in contact_set.laws)


def _cohesive_constraints(contact_set):
    """Per constraint, whether its law has a cohesion."""
    c = contact_set
    return np.array([c.laws[b].cohesion > 0 for b in c.boundary[:len(c.dofs)]], dtype=bool)


def break_pulled_bonds(contact_set, closed, first):
    """After a failed solve: breaks the bond of each cohesive frictional
    constraint that `closed` (the VI's frictional constraints' flags in
    its clamped start, closed_when_clamped; this rank's from position
    `first`; none before a clamped start: all hold) does not hold closed;
    whether any broke here."""
    c = contact_set
    frictional = np.flatnonzero(c.frictional[:len(c.dofs)])
    held = np.ones(len(frictional), dtype=bool)
    given = np.asarray(closed[first:first + len(frictional)], dtype=bool)
    held[:len(given)] = given
    pulled = ~held
    breaking = frictional[pulled & c.bonded[frictional] & _cohesive_constraints(c)[frictional]]
    c.bonded[breaking] = False
    return len(breaking) > 0


def break_open_bonds(contact_set, closed):
    """At an accepted step: breaks the bond of each constraint not closed
    in `closed` (per constraint, ActiveSet's flags); whether any broke
    here."""
    c = contact_set
    breaking = c.bonded & ~np.asarray(closed, dtype=bool)
    c.bonded &= ~breaking
    return bool(np.any(breaking))


def broken_bond_names(contact_set, bonded, comm):
    """The names (constraint_keys) of the cohesive constraints whose bond
    `bonded` holds broken, every rank's, sorted (collective)."""
    keys = constraint_keys(contact_set)
    mine = keys[~np.asarray(bonded, dtype=bool) & _cohesive_constraints(contact_set)] if len(keys) else keys
    return sorted(float(k) for part in comm.allgather(mine.tolist()) for k in part)


def bonds_from_names(contact_set, broken):
    """Per constraint, whether its bond holds when `broken` names the
    broken ones."""
    return ~np.isin(constraint_keys(contact_set).astype(float), np.asarray(broken, dtype=float))
