"""Small dense matrices for the contact algebra's unit tests, the twin of
tests/unit/dense.h: a symmetric positive definite one, and PETSc copies
(AIJ matrices and vectors on one rank) to hand to the code under test."""
import numpy as np
from petsc4py import PETSc


def spd_matrix(n):
    """A_ij = 1 / (1 + |i - j|) + n delta_ij: full, symmetric, and positive
    definite (strictly diagonally dominant: the off-diagonal sum of a row is
    below 2 (1/2 + ... + 1/n) < n)."""
    i = np.arange(n)
    return 1.0 / (1 + np.abs(i[:, None] - i[None, :])) + n * np.eye(n)


def petsc_matrix(A):
    """A as a PETSc AIJ matrix on COMM_WORLD (one rank)."""
    n = A.shape[0]
    M = PETSc.Mat().createAIJ([n, n], nnz=n, comm=PETSc.COMM_WORLD)
    M.setUp()
    rows = np.arange(n, dtype=PETSc.IntType)
    M.setValues(rows, rows, A)
    M.assemble()
    return M


def petsc_vector(M, values):
    """A vector like M's columns holding `values`."""
    v = M.createVecRight()
    v.getArray()[:] = values
    return v
