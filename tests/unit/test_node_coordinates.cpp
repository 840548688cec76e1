// Unit tests of the node coordinates of a P1 space
// (cpp/assembly/node_coordinates.h): the mesh's own node coordinates, bit
// for bit, in the layout of tabulate_dof_coordinates (and equal to it to
// round-off), for a vector space and a collapsed component; a space that
// is not P1 is refused; expressions interpolated into a P1 space are
// evaluated there (sqrt(x) at x = 0 is 0, not NaN). The prototype's twin is
// tests/unit/test_node_coordinates.py.
#include "assembly/node_coordinates.h"
#include "assembly/parameters.h"

#include <basix/finite-element.h>
#include <dolfinx/fem/Function.h>
#include <dolfinx/fem/utils.h>
#include <dolfinx/mesh/generation.h>
#include <dolfinx/mesh/utils.h>
#include <gtest/gtest.h>
#include <set>

using namespace biotcontact;
using namespace dolfinx;

namespace
{
std::shared_ptr<fem::FunctionSpace> lagrange(std::shared_ptr<mesh::Mesh> mesh, int degree, int bs)
{
  const auto cell = mesh::cell_type_to_basix_type(mesh->topology().cell_type());
  const auto variant = degree == 0 ? basix::element::lagrange_variant::unset
                                   : basix::element::lagrange_variant::equispaced;
  const basix::FiniteElement e = basix::create_element(basix::element::family::P, cell, degree, variant, degree == 0);
  return std::make_shared<fem::FunctionSpace>(fem::create_functionspace(mesh, e, bs));
}

/// Each node's coordinates are some mesh node's, exactly, and within
/// round-off of the pushed-forward ones.
void expect_mesh_nodes(const fem::FunctionSpace& V)
{
  const std::vector<double> x = node_coordinates(V), pushed = V.tabulate_dof_coordinates(false);
  ASSERT_EQ(x.size(), pushed.size());
  const std::span<const double> g = V.mesh()->geometry().x();
  std::set<std::array<double, 3>> mesh_nodes;
  for (std::size_t i = 0; i < g.size(); i += 3)
    mesh_nodes.insert({g[i], g[i + 1], g[i + 2]});
  for (std::size_t i = 0; i < x.size(); i += 3)
  {
    EXPECT_TRUE(mesh_nodes.count({x[i], x[i + 1], x[i + 2]})) << "node " << i / 3;
    for (int k = 0; k < 3; ++k)
      EXPECT_NEAR(x[i + k], pushed[i + k], 1e-14);
  }
}
} // namespace

TEST(NodeCoordinates, AreTheMeshNodesOfAVectorSpaceAndItsComponents)
{
  auto rectangle = std::make_shared<mesh::Mesh>(mesh::create_rectangle(
      MPI_COMM_SELF, {{{0, 0}, {4, 1}}}, {12, 5}, mesh::CellType::triangle, mesh::GhostMode::none,
      mesh::DiagonalType::crossed));
  auto V = lagrange(rectangle, 1, 2);
  expect_mesh_nodes(*V);
  expect_mesh_nodes(V->sub({1})->collapse().first);
  auto box = std::make_shared<mesh::Mesh>(mesh::create_box(MPI_COMM_SELF, {{{-1, 0, 0}, {1, 1, 1}}}, {3, 4, 2},
                                                          mesh::CellType::tetrahedron, mesh::GhostMode::none));
  expect_mesh_nodes(*lagrange(box, 1, 3));
}

TEST(NodeCoordinates, RefuseASpaceThatIsNotP1)
{
  auto rectangle = std::make_shared<mesh::Mesh>(mesh::create_rectangle(
      MPI_COMM_SELF, {{{0, 0}, {1, 1}}}, {2, 2}, mesh::CellType::triangle, mesh::GhostMode::none));
  EXPECT_THROW(node_coordinates(*lagrange(rectangle, 2, 1)), std::logic_error);
  EXPECT_THROW(node_coordinates(*lagrange(rectangle, 0, 1)), std::logic_error);
}

TEST(NodeCoordinates, InterpolationIntoP1EvaluatesAtTheMeshNodes)
{
  auto rectangle = std::make_shared<mesh::Mesh>(mesh::create_rectangle(
      MPI_COMM_SELF, {{{0, 0}, {4, 1}}}, {12, 5}, mesh::CellType::triangle, mesh::GhostMode::none));
  fem::Function<double> f(lagrange(rectangle, 1, 2));
  interpolate(f, {Expression("sqrt(x)"), Expression("y - t")}, 0.5);
  const std::vector<double> x = node_coordinates(*f.function_space());
  const std::span<const double> values = f.x()->array();
  for (std::size_t node = 0; node < x.size() / 3; ++node)
  {
    EXPECT_EQ(values[2 * node], std::sqrt(x[3 * node]));
    EXPECT_EQ(values[2 * node + 1], x[3 * node + 1] - 0.5);
  }
  EXPECT_THROW(interpolate(f, {Expression("x")}, 0.0), std::logic_error);
}
