"""The contact constraints of a displacement space, whatever pairs them (a
face against a rigid foundation: foundation_pair.py; the two faces of a
fault: fault_pair.py): per constraint the DOF that carries it after the
change of variables, its gap, normal and lumped measure, and the blocks of
that change, and the contact law of each contact boundary
(cpp/contact/contact_set.h)."""
import dataclasses
import numpy as np
from mpi4py import MPI
from dolfinx import fem, la

from ..assembly.linear_algebra import accumulate_ghosts, add_vector


class ContactSet:
    """The contact constraints of a P1 displacement space V: one for each
    node of a contact boundary (owned by this rank) and each foundation it
    touches (two at the apex of a groove), u.nu_F <= g_a, and one for each
    fault pair whose + node this rank owns. Per constraint: `dofs`, the DOF
    in V (unrolled) that carries u.nu_F = sign * x'[dof] after the change of
    variables (sign +-1 at a node whose normals are coordinate axes, where
    the DOF is that component of u itself; +1 at a transformed node), `gap`,
    `normal`, `lumped` (boundary measure, which turns a nodal force into a
    pressure), `boundary` (its contact boundary or fault in `boundaries`; a
    constraint merged from two boundaries counts for the first),
    `output_dofs` (its node in the P1 scalar `output_space`) and, for a
    fault pair's constraint, `pair_node` (the input index of its + node)
    and `pair_frame` (R, the rotation of the pair's jump:
    pair_change_of_variables); for a foundation's constraint -1, and
    T_node where the node has a change of variables (a frictional one
    always does: its rows 1..d-1 are the tangents friction acts along),
    None elsewhere; `frictional`, whether friction acts on it (its law
    holds something and no displacement component of its node is
    prescribed; then rows 1..d-1 of its change of variables, at dofs[k] +
    1.., are its tangents); `shear_modulus`, the rock's G at a fault pair's
    + node (0 for a foundation's), whose product with the slip is the
    seismic moment (pair_shear_moduli); `junction_nodes`, at a fault pair
    where faults cross or end on one another (fault_pair.py), the global
    nodes of V of its + and - nodes, (-1, -1) elsewhere: its row of x' is
    its normal jump alone (junction_change_of_variables), so its slip is
    measured on u (junction_jumps), and it is frictionless;
    `all_junction_nodes`, every junction's nodes, on every rank. `faults` flags the entries of `boundaries`
    that are faults, `laws` holds the contact law of each (contact_law.py;
    frictionless until the scene gives friction); `bonded`, per constraint,
    whether its cohesion still holds (contact_law.py, "the bond"; empty or 1
    until its pair opens: the ContactSolver keeps it). `blocks` lists the blocks
    of the change of variables as (the global unrolled DOFs of V they mix,
    their matrix): the nodes whose normals are not coordinate axes and the
    node pairs of faults; `dof_offset` is the global index in V of this
    rank's first owned DOF. Filled as lists by the pairs, made arrays by
    contact.locate_contact."""

    def __init__(self, dim, output_space, dof_offset):
        self.dim, self.output_space, self.dof_offset = dim, output_space, dof_offset
        self.dofs, self.sign, self.gap, self.lumped, self.normal, self.output_dofs = [], [], [], [], [], []
        self.boundary, self.boundaries, self.faults, self.laws = [], [], [], []
        self.pair_node, self.pair_frame, self.frictional, self.bonded = [], [], [], []
        self.junction_nodes, self.all_junction_nodes = [], []
        self.shear_modulus = np.zeros(0)
        self.blocks = []


def prescribed_dofs(scene, domain, V):
    """Flags of the DOFs of V (unrolled, local, ghosts too) whose value a
    displacement condition prescribes."""
    imap, bs = V.dofmap.index_map, V.dofmap.index_map_bs
    prescribed = np.zeros(bs * (imap.size_local + imap.num_ghosts), dtype=bool)
    for name, b in scene.boundaries.items():
        for i in range(domain.dim):
            if b.displacement[i] is not None:
                prescribed[fem.locate_dofs_topological(V.sub(i), domain.dim - 1, domain.boundaries[name])] = True
    return prescribed


def lumped_measure(domain, F, V, facets):
    """The lumped boundary measure of each DOF of V (unrolled, local) on
    `facets`: the integral of its hat function over them."""
    lumped = fem.Function(V)
    add_vector(lumped, F.compile("L_lumped_boundary", domain.marker(facets=facets)))
    accumulate_ghosts(lumped)
    return lumped.x.array


def constraint_law(contact_set, k):
    """The law of constraint k: its boundary's, without the cohesion once its
    bond broke (contact_law.py)."""
    law = contact_set.laws[contact_set.boundary[k]]
    if len(contact_set.bonded) and not contact_set.bonded[k]:
        law = dataclasses.replace(law, cohesion=0.0)
    return law


def any_frictional(contact_set, comm):
    """Whether any rank has a frictional constraint (collective)."""
    return comm.allreduce(bool(np.any(contact_set.frictional)), op=MPI.LOR)


def displacement_scale(contact_set, displacement_dofs, x, comm):
    """The displacement scale of x (the solved vector, V's owned DOF i at
    displacement_dofs[i]): the largest gap or |displacement|, 1 when both
    are 0; the contact VI works in its units (collective)."""
    local = max(np.asarray(contact_set.gap).max(initial=0.0),
                np.abs(x.getArray(readonly=True)[displacement_dofs]).max(initial=0.0))
    s = comm.allreduce(float(local), op=MPI.MAX)  # a float pickles in a tenth of numpy's time
    return s if s > 0 else 1.0


def pair_shear_moduli(contact_set, V, G):
    """The shear modulus of each constraint of `contact_set`: at a fault
    pair, the mean of the DG0 coefficient G over the cells of its + node
    (all of them on the + side of the split; a node on a layer interface has
    cells of both layers); 0 at a foundation's constraint (collective)."""
    # Per node, the sum of G and the count of its cells, each cell counted on
    # the rank that owns it and summed onto the node's owner: the same mean
    # on any partition.
    cells = V.mesh.topology.index_map(V.mesh.topology.dim)
    nodes = V.dofmap.index_map
    total, count = la.vector(nodes, 1), la.vector(nodes, 1)
    g = G.x.array
    for c in range(cells.size_local):
        node = V.dofmap.cell_dofs(c)
        np.add.at(total.array, node, g[G.function_space.dofmap.cell_dofs(c)[0]])
        np.add.at(count.array, node, 1.0)
    total.scatter_reverse(la.ScatterMode.add)
    count.scatter_reverse(la.ScatterMode.add)
    bs = V.dofmap.index_map_bs
    moduli = np.zeros(len(contact_set.dofs))
    for k in np.flatnonzero(np.asarray(contact_set.pair_node) >= 0):  # its + node, owned here
        node = contact_set.dofs[k] // bs
        moduli[k] = total.array[node] / count.array[node]
    return moduli


def contact_boundary_flag(contact_set):
    """The contact boundary as a P1 field for output: exactly 1 at the
    contact nodes, 0 elsewhere."""
    flag = fem.Function(contact_set.output_space, name="contact_boundary")
    flag.x.array[contact_set.output_dofs] = 1.0
    flag.x.scatter_forward()
    return flag


def make_contact_fields(contact_set):
    """The output fields of a contact set: the contact pressure and active
    flag (zero off Gamma_3) and the contact_boundary_flag."""
    return (fem.Function(contact_set.output_space), fem.Function(contact_set.output_space),
            contact_boundary_flag(contact_set))
