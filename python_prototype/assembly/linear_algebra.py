"""Assembly helpers shared by the steps (cpp/assembly/linear_algebra.cpp); how systems
are solved: solver.py.

Right-hand sides are Functions used as vectors: `.x.array` holds owned and
ghost entries (assembly adds into both), `.vector` is the PETSc view.
"""
import ctypes

import numpy as np
from dolfinx import fem
from dolfinx.cpp.la import ScatterMode
from mpi4py import MPI
from petsc4py import PETSc

from .node_coordinates import node_coordinates


class UnknownsPart:
    """One field within a vector of unknowns: its own (collapsed) space and
    the position in the vector of each of its local entries (None: the
    vector is the field's own). A checkpoint stores the unknowns field by field."""

    def __init__(self, name, space, position=None):
        self.name, self.space, self.position = name, space, position


def assemble_matrix(a, bcs):
    """Rows and columns of Dirichlet DOFs become identity rows."""
    A = fem.petsc.assemble_matrix(a, bcs)
    A.assemble()
    return A


def reassemble_matrix(A, a, bcs):
    """Assembles a into A (same sparsity); its solvers refactorise it at their next solve."""
    A.zeroEntries()
    fem.petsc.assemble_matrix(A, a, bcs)
    A.assemble()


def assemble_operator(a, bcs):
    """A bilinear form acting on an iterate, applied with a product every
    coupling iteration (cpp/assembly/linear_algebra.cpp): rows of Dirichlet DOFs of its
    test space are zero (no diagonal: the spaces differ)."""
    A = fem.petsc.create_matrix(a)
    reassemble_operator(A, a, bcs)
    return A


def reassemble_operator(A, a, bcs):
    A.zeroEntries()
    fem.petsc.assemble_matrix(A, a, bcs)
    A.assemble()


def multiply_add(A, x, y):
    """y += A x on the owned parts of the Functions x and y (collective)."""
    A.multAdd(x.vector, y.vector, y.vector)


def add_vector(b, L):
    """Adds the local contributions of L to the Function-vector b (ghosts too)."""
    fem.assemble_vector(b.x.array, L)


def accumulate_ghosts(b):
    b.x.scatter_reverse(ScatterMode.add)


def finish_rhs(b, a, bcs):
    """Lifts the Dirichlet values of `a`, accumulates ghosts, sets the Dirichlet rows."""
    if bcs:
        fem.apply_lifting(b.x.array, [a], [bcs])
    accumulate_ghosts(b)
    if bcs:
        fem.set_bc(b.x.array, bcs)


def owned(V):
    """Number of owned (unrolled) DOFs of V on this rank."""
    return V.dofmap.index_map.size_local * V.dofmap.index_map_bs


def owned_norm(x, V, comm):
    """Euclidean norm of the owned part of a DOF array (collective)."""
    n = owned(V)
    return np.sqrt(comm.allreduce(float(np.dot(x[:n], x[:n])), op=MPI.SUM))


def solved_positions(dofs, start, displacement_dofs, dof_offset, comm):
    """The global position in a solved vector (its rows from `start` on this
    rank) of each global DOF of V in `dofs`, wherever it is owned:
    `displacement_dofs[i]` is the place of V's owned DOF i, `dof_offset` the
    global index of this rank's first. A fault's other face may be owned by
    another rank, so every request goes to every rank (collective)."""
    owned = len(displacement_dofs)
    requests = comm.allgather(np.asarray(dofs, dtype=np.int64))
    everything = np.concatenate(requests)
    local = everything - dof_offset
    mine = (local >= 0) & (local < owned)
    answer = np.full(len(everything), -1, dtype=np.int64)
    answer[mine] = start + np.asarray(displacement_dofs)[local[mine]]
    comm.Allreduce(MPI.IN_PLACE, answer, op=MPI.MAX)
    offset = sum(len(r) for r in requests[:comm.rank])
    return answer[offset:offset + len(dofs)]


def largest_entry(x, dofs, comm):
    """The largest |x[i]| over the positions `dofs` on every rank (collective)."""
    return comm.allreduce(float(np.max(np.abs(x[dofs]), initial=0.0)), op=MPI.MAX)


def dof_map(space, sub):
    """For every DOF of `space` (unrolled, ghosts too) its DOF in the parent
    of `sub`, a subspace with the same element (cpp collapse() maps)."""
    collapsed, to_parent = sub.collapse()
    bs = space.dofmap.index_map_bs
    im = space.dofmap.index_map
    node = np.empty(im.size_local + im.num_ghosts, dtype=np.int64)
    node[space.dofmap.list.array] = collapsed.dofmap.list.array
    unrolled = (bs * node[:, None] + np.arange(bs)).ravel()
    return np.asarray(to_parent)[unrolled]


def rigid_body_modes(V, position=None):
    """The rigid-body modes of the P1 vector space V, orthonormalised
    (cpp/assembly/linear_algebra.h): the near-nullspace AMG builds coarse spaces from.
    With `position`, laid out for another numbering of V's owned DOFs (owned
    DOF i is entry position[i]); a node's components must stay together."""
    d = V.dofmap.index_map_bs
    nodes = V.dofmap.index_map.size_local
    coordinates = PETSc.Vec().createMPI((d * nodes, PETSc.DECIDE), bsize=d, comm=V.mesh.comm)
    values = node_coordinates(V)[:nodes, :d].reshape(-1)
    if position is None:
        coordinates.getArray()[:] = values
    else:
        if np.any(position % d != np.arange(d * nodes) % d):
            raise RuntimeError("rigid_body_modes: the numbering splits the components of a node")
        coordinates.getArray()[position] = values
    return PETSc.NullSpace().createRigidBody(coordinates)


def placement(V, V_to_X, X):
    """The matrix R that places V's DOFs in a mixed space X of which V is a
    collapsed part: R(i, V_to_X[i]) = 1 for V's owned DOFs i (global rows of
    V, columns of X; X has block size 1 and owns V's owned DOFs). An
    operator M on V acts on X as M R."""
    rows, columns = owned(V), owned(X)
    first_row = V.dofmap.index_map.local_range[0] * V.dofmap.index_map_bs
    first_column = X.dofmap.index_map.local_range[0]
    R = PETSc.Mat().createAIJ(((rows, None), (columns, None)), nnz=(1, 1), comm=V.mesh.comm)
    for i in range(rows):
        R.setValue(first_row + i, first_column + int(V_to_X[i]), 1.0)
    R.assemble()
    return R


def owned_global_dofs(index_map, local):
    """PETSc's global indices of the local DOFs `local` (block size 1) that
    this rank owns, ascending."""
    local = np.asarray(local)
    owned_local = local[local < index_map.size_local]
    return np.sort(index_map.local_range[0] + owned_local).astype(PETSc.IntType)


def set_lag_preconditioner(snes, lag):
    """SNESSetLagPreconditioner, which petsc4py 3.18 does not wrap: called in
    the PETSc library petsc4py itself loaded, on the object's handle."""
    petsc = ctypes.CDLL(PETSc.__file__, mode=ctypes.RTLD_GLOBAL)
    set_lag = petsc.SNESSetLagPreconditioner
    set_lag.argtypes = (ctypes.c_void_p, ctypes.c_int32 if PETSc.IntType == np.int32 else ctypes.c_int64)
    set_lag.restype = ctypes.c_int
    if set_lag(snes.handle, lag) != 0:
        raise RuntimeError("SNESSetLagPreconditioner failed")
