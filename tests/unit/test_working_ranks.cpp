// Unit tests of the working ranks (cpp/domain/working_ranks.h): the ranks a
// mesh is distributed over, at least one and at most those started, none
// dropped with cells_per_rank = 0; the built-in meshes' cells as dolfinx
// makes them; the default per dimension; what `auto` divides its
// crossovers by on more ranks. The prototype's twin is
// tests/unit/test_working_ranks.py.
#include "domain/working_ranks.h"
#include "solvers/solver.h"

#include <dolfinx/common/IndexMap.h>
#include <dolfinx/mesh/generation.h>
#include <gtest/gtest.h>

using namespace biotcontact;

TEST(WorkingRanks, EachWorkingRankHoldsAtLeastItsShare)
{
  EXPECT_EQ(working_ranks(4720, 8000, 2), 1);   // fault_reactivation
  EXPECT_EQ(working_ranks(23622, 8000, 2), 2);  // sneddon
  EXPECT_EQ(working_ranks(23622, 8000, 4), 2);
  EXPECT_EQ(working_ranks(16000, 8000, 2), 2);  // exactly two shares
  EXPECT_EQ(working_ranks(15999, 8000, 2), 1);
  EXPECT_EQ(working_ranks(10, 8000, 1), 1);
  EXPECT_EQ(working_ranks(0, 8000, 3), 1);      // at least one
  EXPECT_EQ(working_ranks(1000000, 2000, 8), 8); // at most those started
}

TEST(WorkingRanks, ZeroCellsPerRankLetsEveryRankWork)
{
  EXPECT_EQ(working_ranks(10, 0, 4), 4);
  EXPECT_EQ(working_ranks(0, 0, 2), 2);
}

TEST(WorkingRanks, BuiltInCellsAreThoseDolfinxMakes)
{
  using namespace dolfinx;
  MeshSpec rectangle{MeshType::rectangle, {0, 0}, {4, 1}, {12, 5}, "", 2, 0};
  const mesh::Mesh r = mesh::create_rectangle(MPI_COMM_SELF, {{{0, 0}, {4, 1}}}, {12, 5}, mesh::CellType::triangle,
                                              mesh::GhostMode::none, mesh::DiagonalType::crossed);
  EXPECT_EQ(built_in_cells(rectangle), r.topology().index_map(2)->size_global());
  MeshSpec box{MeshType::box, {0, 0, 0}, {1, 1, 1}, {3, 4, 2}, "", 3, 0};
  const mesh::Mesh b = mesh::create_box(MPI_COMM_SELF, {{{0, 0, 0}, {1, 1, 1}}}, {3, 4, 2},
                                        mesh::CellType::tetrahedron, mesh::GhostMode::none);
  EXPECT_EQ(built_in_cells(box), b.topology().index_map(3)->size_global());
}

TEST(WorkingRanks, TetrahedraWorkFromFewerCellsThanTriangles)
{
  EXPECT_LT(default_cells_per_rank(3), default_cells_per_rank(2));
  EXPECT_EQ(SolverSpec{}.cells_per_rank, default_cells_per_rank(2));
}

TEST(WorkingRanks, AutoKeepsThe3DMechanicsCrossoverOnTwoRanks)
{
  EXPECT_EQ(crossover_divisor(true, 1), 1);
  EXPECT_EQ(crossover_divisor(true, 2), 1);
  EXPECT_EQ(crossover_divisor(true, 4), 2);
  EXPECT_EQ(crossover_divisor(false, 2), 2);
  EXPECT_EQ(crossover_divisor(false, 0), 1);
  const auto automatic = [](Structure s, std::int64_t n, int ranks)
  { return choose_method(SolverChoice::automatic, s, n, 3, ranks, false).method; };
  // scenes/injection_fault3d.toml's mechanics (15,186 unknowns) and its flow (81,820)
  EXPECT_EQ(automatic(Structure::spd, 15186, 2), Method::direct);
  EXPECT_EQ(automatic(Structure::quasi_definite, 81820, 2), Method::iterative);
  EXPECT_EQ(automatic(Structure::spd, 44793, 2), Method::iterative); // indenter3d
  EXPECT_EQ(automatic(Structure::quasi_definite, 30000, 2), Method::iterative);
  EXPECT_EQ(automatic(Structure::quasi_definite, 30000, 1), Method::direct);
}
