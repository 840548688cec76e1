"""Unit tests of the quick analysis of repeated factorisations
(python_prototype/contact/factorization_reuse.py), the twins of
tests/unit/test_quick_analysis.cpp: MUMPS analyses by AMD a matrix of
at most QUICK_ANALYSIS_ROWS rows, also a copy on each rank, and leaves a
larger one, another package and a user's choice alone."""
import os
import sys
import unittest

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
import support  # noqa: E402,F401  (the repository on sys.path)
from petsc4py import PETSc  # noqa: E402
from python_prototype.contact.factorization_reuse import QUICK_ANALYSIS_ROWS, analyse_quickly  # noqa: E402


def ordering(options, prefix, rows):
    """The ordering analyse_quickly chose for `prefix` after `options` were
    given, as "mine|redundant copy's"."""
    given = PETSc.Options()
    for name, value in options.items():
        given.setValue(name, value)
    K = PETSc.Mat().createAIJ([rows, rows], nnz=0, comm=PETSc.COMM_SELF)
    analyse_quickly(prefix, K)
    K.destroy()
    return "|".join(given.getString(p + "mat_mumps_icntl_7", "") for p in (prefix, prefix + "redundant_"))


class QuickAnalysisTest(unittest.TestCase):
    def test_mumps_analyses_by_amd_up_to_the_limit(self):
        self.assertEqual(ordering({"qa1_pc_factor_mat_solver_type": "mumps"}, "qa1_", 1000), "0|")
        self.assertEqual(ordering({"qa2_pc_factor_mat_solver_type": "mumps"}, "qa2_", QUICK_ANALYSIS_ROWS), "0|")
        self.assertEqual(ordering({"qa3_pc_type": "redundant", "qa3_redundant_pc_factor_mat_solver_type": "mumps"},
                                  "qa3_", 1000), "|0")

    def test_larger_systems_other_packages_and_the_user_keep_theirs(self):
        self.assertEqual(ordering({"qa4_pc_factor_mat_solver_type": "mumps"}, "qa4_", QUICK_ANALYSIS_ROWS + 1), "|")
        self.assertEqual(ordering({"qa5_pc_factor_mat_solver_type": "umfpack"}, "qa5_", 1000), "|")
        self.assertEqual(ordering({"qa6_pc_factor_mat_solver_type": "mumps", "qa6_mat_mumps_icntl_7": "5"},
                                  "qa6_", 1000), "5|")


if __name__ == "__main__":
    unittest.main()
