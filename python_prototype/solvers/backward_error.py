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


def _absolute_values(A):
    """|A|, the entries' magnitudes in a matrix of A's layout (this rank's
    rows, any AIJ type)."""
    rows, columns, values = A.getValuesCSR()
    B = A.duplicate(copy=False)
    B.setValuesCSR(rows, columns, np.abs(values))
    B.assemble()
    return B


def backward_error(A, x, b, r):
    """max_i |r_i| / (|A| |x| + |b|)_i with r = b - A x, left in r; a row
    whose denominator is 0 has r_i = 0 and counts 0 (collective)."""
    A.mult(x, r)
    r.aypx(-1.0, b)
    B = _absolute_values(A)
    magnitude, scale = x.duplicate(), b.duplicate()
    x.copy(magnitude)
    magnitude.abs()
    B.mult(magnitude, scale)
    b.copy(magnitude)  # now |b|, in b's layout
    magnitude.abs()
    scale.axpy(1.0, magnitude)
    r.copy(magnitude)
    magnitude.abs()
    magnitude.pointwiseDivide(magnitude, scale)  # 0 where the divisor is 0
    error = magnitude.norm(PETSc.NormType.NORM_INFINITY)
    for v in (magnitude, scale, B):
        v.destroy()
    return error
