"""Unit tests of the prototype's working ranks
(python_prototype/domain/working_ranks.py), the twins of
tests/unit/test_working_ranks.cpp: the ranks a mesh is distributed over,
at least one and at most those started, none dropped with cells_per_rank =
0; the built-in meshes' cells as dolfinx makes them; the default per
dimension; what `auto` divides its crossovers by on more ranks."""
import os
import sys
import unittest

from mpi4py import MPI

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
import support  # noqa: E402,F401  (the repository on sys.path)
from dolfinx import mesh as dmesh  # noqa: E402
from python_prototype.domain.working_ranks import built_in_cells, working_ranks  # noqa: E402
from python_prototype.scene.input import MeshType  # noqa: E402
from python_prototype.scene.input import SolverChoice  # noqa: E402
from python_prototype.scene.schema import MeshSpec, SolverSpec, default_cells_per_rank  # noqa: E402
from python_prototype.solvers.solver import Method, Structure, choose_method, crossover_divisor  # noqa: E402


class WorkingRanksTest(unittest.TestCase):
    def test_each_working_rank_holds_at_least_its_share(self):
        self.assertEqual(working_ranks(4720, 8000, 2), 1)  # fault_reactivation
        self.assertEqual(working_ranks(23622, 8000, 2), 2)  # sneddon
        self.assertEqual(working_ranks(23622, 8000, 4), 2)
        self.assertEqual(working_ranks(16000, 8000, 2), 2)  # exactly two shares
        self.assertEqual(working_ranks(15999, 8000, 2), 1)
        self.assertEqual(working_ranks(10, 8000, 1), 1)
        self.assertEqual(working_ranks(0, 8000, 3), 1)  # at least one
        self.assertEqual(working_ranks(1000000, 2000, 8), 8)  # at most those started

    def test_zero_cells_per_rank_lets_every_rank_work(self):
        self.assertEqual(working_ranks(10, 0, 4), 4)
        self.assertEqual(working_ranks(0, 0, 2), 2)

    def test_built_in_cells_are_those_dolfinx_makes(self):
        rectangle = MeshSpec(MeshType.rectangle, [0, 0], [4, 1], [12, 5], "", 2)
        r = dmesh.create_rectangle(MPI.COMM_SELF, [[0, 0], [4, 1]], [12, 5], dmesh.CellType.triangle,
                                   dmesh.GhostMode.none, diagonal=dmesh.DiagonalType.crossed)
        self.assertEqual(built_in_cells(rectangle), r.topology.index_map(2).size_global)
        box = MeshSpec(MeshType.box, [0, 0, 0], [1, 1, 1], [3, 4, 2], "", 3)
        b = dmesh.create_box(MPI.COMM_SELF, [[0, 0, 0], [1, 1, 1]], [3, 4, 2], dmesh.CellType.tetrahedron,
                             dmesh.GhostMode.none)
        self.assertEqual(built_in_cells(box), b.topology.index_map(3).size_global)

    def test_tetrahedra_work_from_fewer_cells_than_triangles(self):
        self.assertLess(default_cells_per_rank(3), default_cells_per_rank(2))
        self.assertEqual(SolverSpec().cells_per_rank, default_cells_per_rank(2))

    def test_auto_keeps_the_3d_mechanics_crossover_on_two_ranks(self):
        self.assertEqual([crossover_divisor(True, r) for r in (1, 2, 4)], [1, 1, 2])
        self.assertEqual(crossover_divisor(False, 2), 2)
        self.assertEqual(crossover_divisor(False, 0), 1)

        def automatic(structure, unknowns, ranks):
            return choose_method(SolverChoice.automatic, structure, unknowns, 3, ranks)[0]
        # scenes/injection_fault3d.toml's mechanics (15,186 unknowns) and its flow (81,820)
        self.assertEqual(automatic(Structure.spd, 15186, 2), Method.direct)
        self.assertEqual(automatic(Structure.quasi_definite, 81820, 2), Method.iterative)
        self.assertEqual(automatic(Structure.spd, 44793, 2), Method.iterative)  # indenter3d
        self.assertEqual(automatic(Structure.quasi_definite, 30000, 2), Method.iterative)
        self.assertEqual(automatic(Structure.quasi_definite, 30000, 1), Method.direct)


if __name__ == "__main__":
    unittest.main()
