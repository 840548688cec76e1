"""The componentwise backward error of a linear solve (Oettli and Prager,
1964; cpp/solvers/backward_error.h): the smallest relative change of the
entries of A and b that x solves exactly. Unlike ||b - A x|| / ||b||, it
stays at the round-off for a good factorisation of a system whose rows lie
1e22 apart, where a package that pivots by magnitude alone leaves it at 1
(docs/theory.md, "What a solve is trusted on")."""
import numpy as np
from petsc4py import PETSc

# The backward error a factorisation's solve must reach (one step of
# iterative refinement leaves a backward stable LU at 1e-16-1e-15; the
# factorisations measured left 5e-16 to 4e-8 before it, 1 where they solved
# wrongly), and the steps of refinement tried before the solve fails.
BACKWARD_ERROR_TOLERANCE = 1e-12
REFINEMENT_STEPS = 3


def absolute_product(A, x, y):
    """y = |A| |x|, the magnitudes of A's entries times those of x's: |A| on
    A's own rows (no communication), then one product, which gathers the
    ghost entries of |x| as for A x (collective). The round-off bound of a
    contact solve's residual takes it too (contact/convergence)."""
    absolute = A.duplicate(copy=False)
    first, last = A.getOwnershipRange()
    for i in range(first, last):
        columns, values = A.getRow(i)
        absolute.setValues([i], columns, np.abs(values), addv=PETSc.InsertMode.INSERT_VALUES)
    absolute.assemble()
    magnitude = x.copy()
    magnitude.abs()
    absolute.mult(magnitude, y)
    magnitude.destroy()
    absolute.destroy()


def backward_error(A, x, b, r):
    """max_i |r_i| / (|A| |x| + |b|)_i with r = b - A x, left in r; a row
    whose denominator is 0 has r_i = 0 and counts 0 (collective)."""
    A.mult(x, r)
    r.aypx(-1.0, b)
    magnitude, scale = b.duplicate(), b.duplicate()
    absolute_product(A, x, scale)
    b.copy(magnitude)
    magnitude.abs()
    scale.axpy(1.0, magnitude)
    r.copy(magnitude)
    magnitude.abs()
    magnitude.pointwiseDivide(magnitude, scale)  # 0 where the divisor is 0
    error = magnitude.norm(PETSc.NormType.NORM_INFINITY)
    magnitude.destroy()
    scale.destroy()
    return error
