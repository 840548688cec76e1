"""Unit tests of the prototype's pieces of a split mesh and their held
rigid motions (python_prototype/domain/pieces.py), the twins of
tests/unit/test_pieces.cpp: two triangles sharing an edge are one piece,
apart two; the rank of the held motions in 2D (normal rows along a line
hold 2 of 3, one more row across it all 3, rows at one point only the
translations) and 3D (a plane's normal at three points holds 3 of 6, the
same along every axis all 6)."""
import os
import sys
import unittest

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
import support  # noqa: E402,F401  (the repository on sys.path)
from python_prototype.domain.faults import InputMesh  # noqa: E402
from python_prototype.domain.pieces import held_motions, mesh_pieces  # noqa: E402


def mesh(x, cells):
    return InputMesh(2, np.array(x, dtype=float), np.array(cells, dtype=np.int64), np.zeros((0, 2), dtype=np.int64),
                     np.zeros(0, dtype=np.int32), [])


class PiecesTest(unittest.TestCase):
    def test_triangles_joined_or_apart(self):
        joined = mesh([[0, 0], [1, 0], [1, 1], [0, 1]], [[0, 1, 2], [0, 2, 3]])
        self.assertEqual(mesh_pieces(joined).tolist(), [0, 0, 0, 0])
        apart = mesh([[0, 0], [1, 0], [1, 1], [0, 1], [2, 2], [3, 2]], [[4, 5, 3], [0, 1, 2]])
        self.assertEqual(mesh_pieces(apart).tolist(), [1, 1, 1, 0, 0, 0])

    def test_held_motions_2d(self):
        centre = (0.5, 0.0, 0.0)
        line, up = [[0, 0], [0.5, 0], [1, 0]], [[0, 1]] * 3
        self.assertEqual(held_motions(line, up, 2, centre, 1.0), 2)
        self.assertEqual(held_motions(line + [[0, 0.5]], up + [[1, 0]], 2, centre, 1.0), 3)
        self.assertEqual(held_motions([[0, 0], [0, 0]], [[1, 0], [0, 1]], 2, centre, 1.0), 2)

    def test_held_motions_3d(self):
        centre = (0.5, 0.5, 0.0)
        plane = [[0, 0, 0], [1, 0, 0], [0, 1, 0]]
        self.assertEqual(held_motions(plane, [[0, 0, 1]] * 3, 3, centre, 1.0), 3)
        points = [p for p in plane for _ in range(3)]
        directions = [e for _ in plane for e in np.eye(3)]
        self.assertEqual(held_motions(points, directions, 3, centre, 1.0), 6)


if __name__ == "__main__":
    unittest.main()
