"""Unit tests of the pins of the prototype's contact VI
(python_prototype/contact/variational_inequality.py, VariationalInequality.pin),
the twins of tests/unit/test_variational_inequality.cpp: on K = [[3, 1/2],
[1/2, 3]] with b = K (2, -1) and y <= 1 at both positions the VI's
solution is (1, -5/6); a position pinned open has no bound (y = (2, -1),
the unconstrained solution); one pinned closed sits on its bound whatever
its force (y = (1, 1), though free y_1 = -5/6 pulls away); no pins, the
VI as posed."""
import os
import sys
import unittest

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
import support  # noqa: E402,F401  (the repository on sys.path)
from dense import petsc_matrix, petsc_vector, spd_matrix  # noqa: E402
from mpi4py import MPI  # noqa: E402
from petsc4py import PETSc  # noqa: E402
from python_prototype.contact.variational_inequality import VariationalInequality, VIProblem  # noqa: E402
from python_prototype.solvers.solver import set_default_option  # noqa: E402


def solved(pins):
    """The VI's solution with `pins` (empty: none)."""
    A = spd_matrix(2)
    K = petsc_matrix(A)
    set_default_option("unit_vi_ksp_type", "preonly")
    set_default_option("unit_vi_pc_type", "lu")
    p = VIProblem(PETSc.COMM_SELF, MPI.COMM_SELF, "unit_vi_", None, "unit", K, petsc_vector(K, [0.0, 0.0]),
                  np.array([0, 1], dtype=np.int32), np.ones(2), np.ones(2))
    vi = VariationalInequality(p, None)
    with vi.load() as b:
        b[:] = A @ np.array([2.0, -1.0])
    vi.unknown().set(0.0)
    vi.pin(pins)
    vi.solve(1.0)
    return vi.unknown().getArray(readonly=True).copy()


class PinTests(unittest.TestCase):
    def test_a_pinned_position_is_on_both_bounds_or_on_none(self):
        np.testing.assert_allclose(solved([]), [1.0, -5.0 / 6.0], atol=1e-10)
        np.testing.assert_allclose(solved([-1, 0]), [2.0, -1.0], atol=1e-10)
        np.testing.assert_allclose(solved([0, 1]), [1.0, 1.0], atol=1e-10)


if __name__ == "__main__":
    unittest.main()
