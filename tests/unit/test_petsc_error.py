"""Unit tests of the ranks' agreement on a PETSc error (agreed_error in
python_prototype/solvers/solver.py), the twins of
tests/unit/test_petsc_error.cpp: an error one rank's call raised reaches
every rank, the largest code where several failed, and none only where all
succeeded. Meant for two ranks (ctest unit.two_ranks runs this module under
mpirun -n 2); on one it checks the error passes through."""
import os
import sys
import unittest

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
import support  # noqa: E402,F401  (the repository on sys.path)
from petsc4py import PETSc  # noqa: E402
from python_prototype.solvers.solver import agreed_error  # noqa: E402

ZERO_PIVOT, OUT_OF_MEMORY = 71, 55  # PETSC_ERR_MAT_LU_ZRPVT, PETSC_ERR_MEM


class PetscError(unittest.TestCase):
    def test_one_ranks_failure_reaches_every_rank(self):
        comm = PETSc.COMM_WORLD
        last = comm.getRank() == comm.getSize() - 1
        self.assertEqual(agreed_error(PETSc.Error(ZERO_PIVOT) if last else None, comm).ierr, ZERO_PIVOT)
        mine = PETSc.Error(OUT_OF_MEMORY if last else ZERO_PIVOT)
        agreed = agreed_error(mine, comm)  # collective: every rank calls it alike
        self.assertEqual(agreed.ierr, ZERO_PIVOT if comm.getSize() > 1 else OUT_OF_MEMORY)
        # the rank whose error it is keeps it, PETSc's words with it
        self.assertEqual(agreed is mine, mine.ierr == agreed.ierr)
        self.assertIsNone(agreed_error(None, comm))


if __name__ == "__main__":
    unittest.main()
