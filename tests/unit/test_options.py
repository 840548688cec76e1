"""Unit tests of the PETSc options the solvers refuse
(python_prototype/solvers/options.py), the twins of
tests/unit/test_options.cpp: SuperLU_DIST named with several OpenMP threads,
under any prefix, is one line naming the option; one thread, or no
SuperLU_DIST, is no error; a relative tolerance outside [0, 1) is one line
naming it."""
import os
import sys
import unittest

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
import support  # noqa: E402,F401  (the repository on sys.path)
from python_prototype.solvers.options import relative_tolerance_out_of_range, threaded_superlu  # noqa: E402


class SolverOptionsTest(unittest.TestCase):
    def test_superlu_with_threads_is_refused_by_its_option(self):
        options = {"mechanics_contact_snes_monitor": "", "flow_pc_factor_mat_solver_type": "superlu_dist",
                   "log_view": ""}
        self.assertEqual(threaded_superlu(options, 2),
                         "-flow_pc_factor_mat_solver_type superlu_dist: SuperLU_DIST solves wrongly with 2 OpenMP "
                         "threads (Debian's 8.1.2: the contact solver cycles, the split diverges); "
                         "set OMP_NUM_THREADS=1")
        self.assertIn("-monolithic_redundant_pc_factor_mat_solver_type superlu_dist:",
                      threaded_superlu({"monolithic_redundant_pc_factor_mat_solver_type": "superlu_dist"}, 8))

    def test_one_thread_or_another_package_is_no_error(self):
        self.assertEqual(threaded_superlu({"flow_pc_factor_mat_solver_type": "superlu_dist"}, 1), "")
        self.assertEqual(threaded_superlu({"flow_pc_factor_mat_solver_type": "mumps",
                                           "mechanics_pc_type": "cholesky"}, 2), "")
        self.assertEqual(threaded_superlu({}, 2), "")

    def test_a_relative_tolerance_outside_zero_to_one_is_refused(self):
        self.assertEqual(relative_tolerance_out_of_range({"log_view": "", "mechanics_snes_rtol": "2",
                                                          "flow_ksp_rtol": "1e-8"}),
                         "-mechanics_snes_rtol 2: a relative tolerance lies in [0, 1) (from 1 on any first iterate "
                         "meets it)")
        self.assertIn("-flow_ksp_rtol -1e-3:", relative_tolerance_out_of_range({"flow_ksp_rtol": "-1e-3"}))
        self.assertIn("-ksp_rtol 1:", relative_tolerance_out_of_range({"ksp_rtol": "1"}))
        self.assertEqual(relative_tolerance_out_of_range({"mechanics_snes_rtol": "0.5", "flow_ksp_rtol": "0",
                                                          "monolithic_ksp_atol": "5"}), "")
        self.assertEqual(relative_tolerance_out_of_range({"flow_ksp_rtol": ""}), "")  # no value: PETSc's own error


if __name__ == "__main__":
    unittest.main()
