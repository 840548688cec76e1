// Unit tests of the pieces of a split mesh and their held rigid motions
// (cpp/domain/pieces.h), with the same cases as the prototype's twin
// tests/unit/test_pieces.py: two triangles sharing an edge are one piece,
// apart two; the rank of the held motions in 2D (normal rows along a line
// hold 2 of 3, one more row across it all 3, rows at one point only the
// translations) and 3D (a plane's normal at three points holds 3 of 6, the
// same along every axis all 6).
#include "domain/pieces.h"

#include <gtest/gtest.h>

using namespace biotcontact;

TEST(Pieces, TrianglesJoinedOrApart)
{
  InputMesh joined{2, {0, 0, 1, 0, 1, 1, 0, 1}, {0, 1, 2, 0, 2, 3}, {}, {}, {}};
  EXPECT_EQ(mesh_pieces(joined), (std::vector<std::int64_t>{0, 0, 0, 0}));
  InputMesh apart{2, {0, 0, 1, 0, 1, 1, 0, 1, 2, 2, 3, 2}, {4, 5, 3, 0, 1, 2}, {}, {}, {}};
  EXPECT_EQ(mesh_pieces(apart), (std::vector<std::int64_t>{1, 1, 1, 0, 0, 0}));
}

TEST(Pieces, HeldMotions2D)
{
  const std::array<double, 3> centre{0.5, 0, 0};
  // The normal (0, 1) at three points of y = 0: the block slides along x.
  const std::vector<double> line{0, 0, 0.5, 0, 1, 0}, up{0, 1, 0, 1, 0, 1};
  EXPECT_EQ(held_motions(line, up, 2, centre, 1.0), 2);
  std::vector<double> points = line, directions = up;
  points.insert(points.end(), {0, 0.5});
  directions.insert(directions.end(), {1, 0});
  EXPECT_EQ(held_motions(points, directions, 2, centre, 1.0), 3);
  EXPECT_EQ(held_motions({0, 0, 0, 0}, {1, 0, 0, 1}, 2, centre, 1.0), 2); // one point: it turns about it
}

TEST(Pieces, HeldMotions3D)
{
  const std::array<double, 3> centre{0.5, 0.5, 0};
  const std::vector<double> plane{0, 0, 0, 1, 0, 0, 0, 1, 0}, up{0, 0, 1, 0, 0, 1, 0, 0, 1};
  EXPECT_EQ(held_motions(plane, up, 3, centre, 1.0), 3);
  std::vector<double> points, directions;
  for (int p = 0; p < 3; ++p)
    for (int axis = 0; axis < 3; ++axis)
    {
      points.insert(points.end(), &plane[3 * p], &plane[3 * p + 3]);
      std::vector<double> e(3, 0.0);
      e[axis] = 1;
      directions.insert(directions.end(), e.begin(), e.end());
    }
  EXPECT_EQ(held_motions(points, directions, 3, centre, 1.0), 6);
}
