"""The whole system a contact VI may be posed on (variational_inequality.py),
and its solve with some unknowns held: the clamped start's (all contact
DOFs on their bounds, every frictional constraint stuck).
Twin: cpp/contact/whole_system.h."""
import dataclasses

from petsc4py import PETSc

from ..solvers.linear_solver import LinearSolver
from ..solvers.solver import Method


@dataclasses.dataclass
class WholeSystem:
    """The whole system a VI is posed on (y = x, K = A): its matrices, fields
    and method. The clamped start solves it with the contact DOFs
    eliminated; the iterative method preconditions the Newton steps from P
    split along the fields (inactive_set_preconditioner.py)."""
    comm: object
    A: PETSc.Mat
    P: PETSc.Mat
    layout: object
    method: Method


def _start_no_worse_than_held(A, b, y, rows):
    """Zeroes y's entries but the held `rows` where y is a worse start than
    that, ||b - A y|| > ||b - A y_held||: a singular first Newton step of a
    body that contact alone holds left y 1e11 off, and an iterative
    solver's convergence test, relative to ||b||, stopped at its first
    iteration (DIVERGED_DTOL; elastic_contact, solver.mechanics =
    "iterative"). A and b are the clamped system's (collective)."""
    held = y.duplicate()
    local = rows - y.getOwnershipRange()[0]
    held.getArray()[local] = y.getArray(readonly=True)[local]

    def residual(x):
        r = b.duplicate()
        A.mult(x, r)
        r.aypx(-1.0, b)
        return r.norm()
    if residual(y) > residual(held):
        held.copy(y)


def solve_clamped(whole, b, y, rows):
    """Solves A y = b with the global rows `rows` held at their values in
    y: their rows and columns eliminated, the known values moved to the
    right-hand side (collective)."""
    def clamped_copy(M, rhs=None):
        # the held rows and columns made identity rows
        C = M.duplicate(copy=True)
        modes = M.getNearNullSpace()  # for AMG: the duplicate does not keep it
        if modes is not None and modes.handle:
            C.setNearNullSpace(modes)
        C.zeroRowsColumns(rows, 1.0, y if rhs is not None else None, rhs)
        return C
    rhs = b.copy()
    A = clamped_copy(whole.A, rhs)
    P = A if whole.P is whole.A else clamped_copy(whole.P)
    _start_no_worse_than_held(A, rhs, y, rows)
    LinearSolver(whole.comm, whole.layout.prefix, A, P, whole.layout.structure, whole.layout.fields).solve(y, rhs)
