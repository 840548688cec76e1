// Unit tests of the pins of the contact's VI (cpp/contact/
// variational_inequality.h, VariationalInequality::pin): on K = [[3, 1/2],
// [1/2, 3]] with b = K (2, -1) and y <= 1 at both positions the VI's
// solution is (1, -5/6); a position pinned open has no bound (y = (2, -1),
// the unconstrained solution); one pinned closed sits on its bound whatever
// its force (y = (1, 1), though free y_1 = -5/6 pulls away); no pins, the
// VI as posed. The prototype's twin is tests/unit/test_variational_inequality.py.
#include "contact/variational_inequality.h"
#include "dense.h"
#include "solvers/solver.h"

#include <array>
#include <gtest/gtest.h>

using namespace biotcontact;

namespace
{
/// The VI's solution with `pins` (empty: none).
std::array<double, 2> solved(std::vector<std::int8_t> pins)
{
  unit::Dense A = unit::spd_matrix(2);
  Mat K = unit::petsc_matrix(A);
  Vec layout = unit::petsc_vector(K, {0.0, 0.0});
  set_default_option("unit_vi_ksp_type", "preonly");
  set_default_option("unit_vi_pc_type", "lu");
  VIProblem p{PETSC_COMM_SELF, "unit_vi_", "", "unit", K, layout, {0, 1}, {1.0, 1.0}, {1.0, 1.0}};
  std::array<double, 2> y{};
  {
    VariationalInequality vi(std::move(p), std::nullopt);
    const std::array<double, 2> b{A(0, 0) * 2 - A(0, 1), A(1, 0) * 2 - A(1, 1)};
    const PetscInt rows[2] = {0, 1};
    VecSetValues(vi.load(), 2, rows, b.data(), INSERT_VALUES);
    VecSet(vi.unknown(), 0.0);
    vi.pin(std::move(pins));
    vi.solve(1.0);
    VecGetValues(vi.unknown(), 2, rows, y.data());
  }
  VecDestroy(&layout);
  MatDestroy(&K);
  return y;
}
} // namespace

TEST(VariationalInequality, APinnedPositionIsOnBothBoundsOrOnNone)
{
  const std::array<double, 2> posed = solved({}), open = solved({-1, 0}), closed = solved({0, 1});
  EXPECT_NEAR(posed[0], 1.0, 1e-10);
  EXPECT_NEAR(posed[1], -5.0 / 6.0, 1e-10);
  EXPECT_NEAR(open[0], 2.0, 1e-10);
  EXPECT_NEAR(open[1], -1.0, 1e-10);
  EXPECT_NEAR(closed[0], 1.0, 1e-10);
  EXPECT_NEAR(closed[1], 1.0, 1e-10);
}
