"""Unit tests of the prototype's node coordinates of a P1 space
(python_prototype/assembly/node_coordinates.py), the twins of
tests/unit/test_node_coordinates.cpp: the mesh's own node coordinates, bit
for bit, in the layout of tabulate_dof_coordinates (and equal to it to
round-off), for a vector space and a collapsed component; a space that is
not P1 is refused; expressions interpolated into a P1 space are evaluated
there (sqrt(x) at x = 0 is 0, not NaN)."""
import os
import sys
import unittest

import numpy as np
from mpi4py import MPI

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
import support  # noqa: E402,F401  (the repository on sys.path)
from dolfinx import fem, mesh as dmesh  # noqa: E402
from python_prototype.assembly.node_coordinates import node_coordinates  # noqa: E402
from python_prototype.assembly.parameters import interpolate  # noqa: E402
from python_prototype.scene.expression import Expression  # noqa: E402


class NodeCoordinatesTest(unittest.TestCase):
    def expect_mesh_nodes(self, V):
        """Each node's coordinates are some mesh node's, exactly, and within
        round-off of the pushed-forward ones."""
        x, pushed = node_coordinates(V), V.tabulate_dof_coordinates()
        self.assertEqual(x.shape, pushed.shape)
        mesh_nodes = {tuple(p) for p in V.mesh.geometry.x}
        self.assertTrue(all(tuple(p) in mesh_nodes for p in x))
        self.assertLessEqual(np.abs(x - pushed).max(), 1e-14)

    def test_are_the_mesh_nodes_of_a_vector_space_and_its_components(self):
        rectangle = dmesh.create_rectangle(MPI.COMM_SELF, [[0, 0], [4, 1]], [12, 5], dmesh.CellType.triangle,
                                           dmesh.GhostMode.none, diagonal=dmesh.DiagonalType.crossed)
        V = fem.VectorFunctionSpace(rectangle, ("Lagrange", 1))
        self.expect_mesh_nodes(V)
        self.expect_mesh_nodes(V.sub(1).collapse()[0])
        box = dmesh.create_box(MPI.COMM_SELF, [[-1, 0, 0], [1, 1, 1]], [3, 4, 2], dmesh.CellType.tetrahedron,
                               dmesh.GhostMode.none)
        self.expect_mesh_nodes(fem.VectorFunctionSpace(box, ("Lagrange", 1)))

    def test_refuse_a_space_that_is_not_p1(self):
        rectangle = dmesh.create_rectangle(MPI.COMM_SELF, [[0, 0], [1, 1]], [2, 2], dmesh.CellType.triangle,
                                           dmesh.GhostMode.none)
        for element in (("Lagrange", 2), ("DG", 0)):
            with self.assertRaises(RuntimeError):
                node_coordinates(fem.FunctionSpace(rectangle, element))

    def test_interpolation_into_p1_evaluates_at_the_mesh_nodes(self):
        rectangle = dmesh.create_rectangle(MPI.COMM_SELF, [[0, 0], [4, 1]], [12, 5], dmesh.CellType.triangle,
                                           dmesh.GhostMode.none)
        f = fem.Function(fem.VectorFunctionSpace(rectangle, ("Lagrange", 1)))
        interpolate(f, [Expression("sqrt(x)"), Expression("y - t")], 0.5)
        x, values = node_coordinates(f.function_space), f.x.array.reshape(-1, 2)
        self.assertTrue(np.array_equal(values[:, 0], np.sqrt(x[:, 0])))
        self.assertTrue(np.array_equal(values[:, 1], x[:, 1] - 0.5))
        with self.assertRaises(RuntimeError):
            interpolate(f, [Expression("x")], 0.0)


if __name__ == "__main__":
    unittest.main()
