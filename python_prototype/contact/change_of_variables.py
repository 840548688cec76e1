"""The change of variables that turns each Signorini constraint into a bound
(cpp/contact/change_of_variables.h; docs/theory.md, "Constraints as
bounds: the change of variables", "Faults"). At a contact node the
constraints nu_j . u <= g_j (m foundations, m <= d) are bounds w_j <= g_j
on w = T u, T's first m rows the normals, completed orthonormally. At a
fault's node pair (u+, u-) the block [[R, -R], [I/2, I/2]], R's first row
nu = -n, makes the jump (in u+'s rows) and the mean (in u-'s) the new
variables; where faults meet one block makes each pair's normal jump one
(junction_change_of_variables). For x' = T x, T block-diagonal, A x = b
becomes A' x' = b', A' = T^{-T} A T^{-1}, b' = T^{-T} b, and the residual
F' = T^{-T} F holds each constraint's multiplier. Without a fault or a
normal off the axes T is never formed."""
import dataclasses

import numpy as np
from mpi4py import MPI
from petsc4py import PETSc


def coordinate_axis(normal, d):
    """(axis, sign) of a unit normal that is a coordinate axis to round-off
    1e-14; None otherwise."""
    axis = None
    for i in range(d):
        if abs(normal[i]) > 1 - 1e-14:
            axis = i
        elif abs(normal[i]) > 1e-14:
            return None
    return None if axis is None else (axis, 1 if normal[axis] > 0 else -1)


def _orthonormal_to(v, rows, d):
    """v less its parts along the orthonormal `rows`, normalised; None when
    nothing (to 1e-8) is left."""
    v = np.array(v[:d], dtype=float)
    for q in rows:
        v -= np.dot(v, q) * q
    length = np.sqrt(np.dot(v, v))
    return None if length < 1e-8 else v / length


def node_change_of_variables(normals, d, prescribed):
    """T_node (d x d) for the unit normals of the foundations at one node,
    or None when they are not independent or the change would mix a
    prescribed displacement component with a free one (every normal must be
    perpendicular to it, or the whole node prescribed)."""
    T, Q = [np.array(n[:d], dtype=float) for n in normals], []
    for n in normals:
        q = _orthonormal_to(n, Q, d)
        if q is None:
            return None
        Q.append(q)
    for axis in range(d):
        if len(T) == d:
            break
        q = _orthonormal_to(np.eye(3)[axis], Q, d)
        if q is not None:
            Q.append(q)
            T.append(q)
    T = np.array(T)
    if abs(np.linalg.det(T)) < 1e-8:
        return None
    if not all(prescribed[:d]):
        for i in range(d):
            if prescribed[i] and any(abs(n[i]) > 1e-12 for n in normals):
                return None
    return T


def pair_change_of_variables(R, d):
    """The 2d x 2d block of a fault's node pair for the rotation R (T_node
    of the constraint normal nu): rows [R, -R] (the jump) and [I/2, I/2]
    (the mean), columns (u+, u-)."""
    R = np.asarray(R)[:d, :d]
    half = 0.5 * np.eye(d)
    return np.block([[R, -R], [half, half]])


@dataclasses.dataclass
class JunctionPair:
    """A fault pair at a junction (where faults cross or end on one
    another), as the junction's block sees it: the positions of its + and -
    nodes among the block's nodes, the row of its + node that carries its
    constraint (0..d-1), and the constraint's normal nu = -n."""
    plus: int
    minus: int
    row: int
    normal: np.ndarray


def _append_orthonormal(v, Q):
    """v less its parts along the rows of Q (orthonormal), normalised and
    appended to Q; False when nothing (to 1e-8 of |v|) is left."""
    norm = np.linalg.norm(v)
    for q in Q:
        v = v - (v @ q) * q
    length = np.linalg.norm(v)
    if length < 1e-8 * norm:
        return False
    Q.append(v / length)
    return True


def junction_change_of_variables(pairs, m, d, prescribed):
    """The block of T at a junction (its m nodes, the pieces around it, d
    DOFs each in node order): row d plus + row of each pair is its
    constraint nu . (u+ - u-), so each is a bound on an unknown of its own;
    the row of each `prescribed` DOF is its unit vector (the DOF stays its
    own unknown); the other rows complete them to a basis, orthonormal and
    orthogonal to the rows before (Gram-Schmidt of the unit vectors).
    Around a junction the jumps of its pairs sum to zero, so they cannot all
    be unknowns as at a lone pair; their normal components are independent
    wherever the faces bounding each piece are not all parallel. None when
    they are not (to 1e-8), or a constraint sits in a prescribed row or
    reaches a prescribed DOF."""
    n = m * d
    prescribed = np.asarray(prescribed, dtype=bool)
    B, Q, taken = np.zeros((n, n)), [], prescribed.copy()
    for j in np.flatnonzero(prescribed):
        B[j, j] = 1.0
        _append_orthonormal(np.eye(n)[j], Q)
    for p in pairs:
        row = d * p.plus + p.row
        v = np.zeros(n)
        v[d * p.plus:d * p.plus + d], v[d * p.minus:d * p.minus + d] = p.normal[:d], -np.asarray(p.normal[:d])
        if np.any(np.abs(v[prescribed]) > 1e-12) or taken[row] or not _append_orthonormal(v, Q):
            return None
        B[row], taken[row] = v, True
    # Each free row: the first unit vector (its own, then the others) that
    # adds a direction, less its parts along the rows so far.
    for row in range(n):
        for k in range(n):
            if taken[row]:
                break
            if _append_orthonormal(np.eye(n)[(row + k) % n], Q):
                B[row], taken[row] = Q[-1], True
    return B


def _block_diagonal(A, blocks, inverted):
    """The identity with the blocks (T's or their inverses) in place: every
    rank adds 1 on its diagonal, each block's rank adds B - I on its rows,
    which another rank may own (collective)."""
    (m, n), (M, N) = A.getLocalSize(), A.getSize()
    start = A.getOwnershipRange()[0]
    width = A.getComm().tompi4py().allreduce(max([len(dofs) for dofs, _ in blocks], default=1), op=MPI.MAX)
    T = PETSc.Mat().createAIJ(((m, M), (n, N)), nnz=(width, width), comm=A.getComm())
    T.setBlockSize(A.getBlockSize())
    T.setUp()
    for i in range(m):
        T.setValue(start + i, start + i, 1.0, addv=PETSc.InsertMode.ADD_VALUES)
    for dofs, block in blocks:
        rows = np.asarray(dofs, dtype=PETSc.IntType)
        B = (np.linalg.inv(block) if inverted else np.asarray(block)) - np.eye(len(rows))
        T.setValues(rows, rows, B, addv=PETSc.InsertMode.ADD_VALUES)
    T.assemble()
    return T


class ChangeOfVariables:
    """The block-diagonal change x' = T x of a system (vectors like A's
    columns); `blocks` are (the global DOFs they mix, on any rank: a fault's
    two faces may be owned by two; their matrix) pairs, each given on one
    rank (collective); `spd`: A is symmetric positive definite (so is A')."""

    def __init__(self, A, blocks, spd):
        self.T = _block_diagonal(A, blocks, False)
        self.T_inverse = _block_diagonal(A, blocks, True)
        self.spd = spd

    def forward(self, x, y):
        """y = T x."""
        self.T.mult(x, y)

    def backward(self, y, x):
        """x = T^{-1} y."""
        self.T_inverse.mult(y, x)

    def dual(self, f, g):
        """g = T^{-T} f: a load or a residual in the new variables."""
        self.T_inverse.multTranspose(f, g)

    def congruence(self, A, At=None):
        """A' = T^{-T} A T^{-1}, reusing At's structure when given; A's
        near-nullspace, transformed, carries over."""
        At = A.PtAP(self.T_inverse, result=At)
        if self.spd:
            At.setOption(PETSc.Mat.Option.SPD, True)
        modes = A.getNearNullSpace()
        if modes is not None and modes.handle:
            At.setNearNullSpace(self.transformed(modes))
        return At

    def transformed(self, modes, dofs=None, layout=None):
        """The vectors T v of a near-nullspace, orthonormalised; they are
        like A's columns, or, given `dofs`, those of a field (global indices
        of their entries in a vector like `layout`)."""
        vectors = []
        for v in modes.getVecs():
            t = v.duplicate()
            if dofs is None:
                self.forward(v, t)
            else:
                start = layout.getOwnershipRange()[0]
                whole, changed = layout.duplicate(), layout.duplicate()
                whole.set(0.0)
                whole.getArray()[np.asarray(dofs) - start] = v.getArray(readonly=True)
                self.forward(whole, changed)
                t.getArray()[:] = changed.getArray(readonly=True)[np.asarray(dofs) - start]
            for q in vectors:
                t.axpy(-t.dot(q), q)
            t.normalize()
            vectors.append(t)
        return PETSc.NullSpace().create(constant=modes.hasConstant(), vectors=vectors, comm=modes.getComm())
