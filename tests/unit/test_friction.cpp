// Unit tests of friction as the VI's equations (cpp/contact/friction.h and
// the return map of contact_law.h): the projection on the disc sticks
// inside, slips onto the bound along theta outside, leaves a constraint
// with bound 0 free, and its derivatives are the finite differences of the
// force; the tangential rows of F are c ds / s where a constraint sticks and
// R_T + bound n / s where it slips; and the generalised Jacobian of
// friction_jacobian is F's finite-difference derivative, in 2D and 3D, on a
// dense SPD K with one constraint stuck, one slipping and one open; and
// its rows' weights (jacobian_weights) change with the states alone in 2D,
// with a slip's trial force in 3D. The
// prototype's twin is tests/unit/test_friction.py.
#include "contact/friction.h"
#include "dense.h"

#include <gtest/gtest.h>

using namespace biotcontact;

namespace
{
/// Three constraints on 9 unknowns (normal, two tangents each), Coulomb
/// mu = 0.5 with cohesion 0.1, bound on the upper side (sign +1) at gap 1:
/// x_N = 1 is closed.
std::vector<FrictionalConstraint> constraints()
{
  std::vector<FrictionalConstraint> c;
  for (PetscInt k = 0; k < 3; ++k)
  {
    FrictionalConstraint f;
    f.normal = 3 * k, f.tangential = {3 * k + 1, 3 * k + 2};
    f.sign = 1, f.gap = 1, f.lumped = 0.5, f.law = {0.5, 0.1, {}};
    c.push_back(f);
  }
  return c;
}

/// F(x) = K x - b plus friction (scale 1, the step's start 0).
std::vector<double> residual(const unit::Dense& K, const std::vector<double>& b, const std::vector<double>& x,
                             int tangents)
{
  std::vector<double> R = unit::product(K, x), start(x.size(), 0.0), c(x.size());
  for (std::size_t i = 0; i < x.size(); ++i)
    R[i] -= b[i], c[i] = K(i, i);
  std::vector<double> F = R;
  add_friction_forces(constraints(), {x.data(), R.data(), start.data(), c.data(), 1.0, tangents}, F.data());
  return F;
}

void expect_jacobian_is_derivative(int tangents)
{
  const unit::Dense K = unit::spd_matrix(9);
  // Constraint 0 closed and stuck (a small tangential load), 1 closed and
  // slipping (a large one), 2 open (x_N below its gap).
  std::vector<double> x = {1.0, 1e-3, -2e-3, 1.0, 0.3, 0.2, 0.5, 0.1, 0.1};
  if (tangents == 1)
    x[2] = x[5] = x[8] = 0;
  const std::vector<double> Kx = unit::product(K, x);
  std::vector<double> b = Kx;
  b[0] += 4.0, b[3] += 4.0; // pressing: t_N = 4 / 0.5 = 8, bound (0.1 + 0.5 * 8) * 0.5
  b[4] -= 30.0;             // constraint 1 loaded far past its bound
  std::vector<double> R = Kx, start(9, 0.0), c(9);
  for (int i = 0; i < 9; ++i)
    R[i] -= b[i], c[i] = K(i, i);
  const FrictionPoint at{x.data(), R.data(), start.data(), c.data(), 1.0, tangents};
  ASSERT_TRUE(friction_term(constraints()[0], at).projection.stick);
  ASSERT_FALSE(friction_term(constraints()[1], at).projection.stick);
  ASSERT_GT(friction_term(constraints()[1], at).bound, 0.0);
  ASSERT_FALSE(friction_term(constraints()[2], at).closed);
  // On a sparse K (the full path's) and a dense one (the condensed H).
  Mat A = unit::petsc_matrix(K), J = nullptr, H = nullptr, G_dense = nullptr;
  MatDuplicate(A, MAT_COPY_VALUES, &J);
  MatSetOption(J, MAT_NEW_NONZERO_ALLOCATION_ERR, PETSC_FALSE);
  ASSERT_EQ(friction_jacobian(constraints(), at, A, J), 0);
  MatConvert(A, MATSEQDENSE, MAT_INITIAL_MATRIX, &H);
  MatDuplicate(H, MAT_COPY_VALUES, &G_dense);
  ASSERT_EQ(friction_jacobian(constraints(), at, H, G_dense), 0);
  const unit::Dense G = unit::dense(J), G2 = unit::dense(G_dense);
  for (int i = 0; i < 9; ++i)
    for (int j = 0; j < 9; ++j)
      EXPECT_NEAR(G2(i, j), G(i, j), 1e-13 * (1 + std::abs(G(i, j)))) << "dense J(" << i << ", " << j << ")";
  MatDestroy(&H);
  MatDestroy(&G_dense);
  const std::vector<double> F = residual(K, b, x, tangents);
  for (int j = 0; j < 9; ++j)
  {
    // One-sided into the bound for the normals (x_N > 1 stays closed).
    const double h = 1e-7;
    std::vector<double> y = x;
    y[j] += h;
    const std::vector<double> Fh = residual(K, b, y, tangents);
    for (int i = 0; i < 9; ++i)
      EXPECT_NEAR(G(i, j), (Fh[i] - F[i]) / h, 1e-5 * (1 + std::abs(G(i, j)))) << "J(" << i << ", " << j << ")";
  }
  MatDestroy(&J);
  MatDestroy(&A);
}
/// jacobian_weights at expect_jacobian_is_derivative's point, with the
/// tangential loads `stuck` on constraint 0 and `slipping` on constraint 1.
std::vector<double> weights_at(int tangents, double stuck, double slipping)
{
  const unit::Dense K = unit::spd_matrix(9);
  std::vector<double> x = {1.0, 1e-3, -2e-3, 1.0, 0.3, 0.2, 0.5, 0.1, 0.1};
  if (tangents == 1)
    x[2] = x[5] = x[8] = 0;
  std::vector<double> R(9, 0.0), start(9, 0.0), c(9);
  for (int i = 0; i < 9; ++i)
    c[i] = K(i, i);
  R[0] = R[3] = -4.0, R[1] = stuck, R[4] = slipping; // R = K x - b
  return jacobian_weights(constraints(), {x.data(), R.data(), start.data(), c.data(), 1.0, tangents});
}
} // namespace

TEST(Friction, JacobianWeightsFollowTheStates)
{
  // 2D: the weights (and so J) change with a constraint's state only.
  const std::vector<double> w = weights_at(1, 0.0, 30.0);
  ASSERT_EQ(w.size(), 15u);
  EXPECT_EQ(weights_at(1, 0.5, 40.0), w) << "stuck and slipping as before: the same J";
  EXPECT_NE(weights_at(1, 30.0, 30.0), w) << "constraint 0 slips";
  EXPECT_NE(weights_at(1, 0.0, -30.0), w) << "constraint 1 slips the other way";
  // 3D: a slipping constraint's D turns with its trial force.
  EXPECT_NE(weights_at(2, 0.0, 40.0), weights_at(2, 0.0, 30.0));
  EXPECT_EQ(weights_at(2, 0.5, 30.0), weights_at(2, 0.0, 30.0)) << "stuck: D = I whatever the load";
}

TEST(Friction, DiscInsideSticks)
{
  const DiscProjection p = project_on_disc(2.0, {1.0, -0.5}, 2);
  EXPECT_TRUE(p.stick);
  EXPECT_EQ(p.force[0], 1.0);
  EXPECT_EQ(p.force[1], -0.5);
  EXPECT_EQ(p.d_trial[0], 1.0);
  EXPECT_EQ(p.d_trial[3], 1.0);
  EXPECT_EQ(p.d_bound[0], 0.0);
}

TEST(Friction, DiscOutsideSlipsOntoTheBound)
{
  const DiscProjection p = project_on_disc(2.0, {3.0, 4.0}, 2);
  EXPECT_FALSE(p.stick);
  EXPECT_DOUBLE_EQ(p.force[0], 1.2);
  EXPECT_DOUBLE_EQ(p.force[1], 1.6);
  EXPECT_DOUBLE_EQ(p.d_bound[0], 0.6);
  // In 2D a slipping constraint's force is bound sign(theta): no d_trial.
  const DiscProjection q = project_on_disc(2.0, {-3.0, 0.0}, 1);
  EXPECT_DOUBLE_EQ(q.force[0], -2.0);
  EXPECT_EQ(q.d_trial[0], 0.0);
  EXPECT_EQ(q.d_bound[0], -1.0);
}

TEST(Friction, BoundZeroLeavesFree)
{
  for (const std::array<double, 2>& trial : {std::array<double, 2>{0.0, 0.0}, {1.0, 2.0}})
  {
    const DiscProjection p = project_on_disc(0.0, trial, 2);
    EXPECT_FALSE(p.stick);
    EXPECT_EQ(p.force[0], 0.0);
    EXPECT_EQ(p.force[1], 0.0);
    for (double d : p.d_trial)
      EXPECT_EQ(d, 0.0);
  }
}

TEST(Friction, DiscDerivativesAreFiniteDifferences)
{
  const std::array<double, 2> trial{3.0, -4.0};
  const double bound = 2.0, h = 1e-7;
  const DiscProjection p = project_on_disc(bound, trial, 2);
  for (int q = 0; q < 2; ++q)
  {
    std::array<double, 2> moved = trial;
    moved[q] += h;
    const DiscProjection m = project_on_disc(bound, moved, 2);
    for (int r = 0; r < 2; ++r)
      EXPECT_NEAR(p.d_trial[2 * r + q], (m.force[r] - p.force[r]) / h, 1e-6);
  }
  const DiscProjection b = project_on_disc(bound + h, trial, 2);
  for (int r = 0; r < 2; ++r)
    EXPECT_NEAR(p.d_bound[r], (b.force[r] - p.force[r]) / h, 1e-6);
}

TEST(Friction, SlopeIsFrictionWherePressed)
{
  EXPECT_EQ(slip_bound_slope(ContactLaw{0.6, 1e6, {}}, 1e6), 0.6);
  EXPECT_EQ(slip_bound_slope(ContactLaw{0.6, 1e6, {}}, -1e6), 0.0);
  EXPECT_EQ(slip_bound_slope(ContactLaw{0.6, 1e6, 2e6}, 1e6), 0.0);
}

TEST(Friction, StuckRowIsTheSlipIncrement)
{
  // Constraint 0 of expect_jacobian_is_derivative's point sticks: its rows
  // of F are c ds (scale 1, start 0), whatever R.
  const unit::Dense K = unit::spd_matrix(9);
  std::vector<double> x = {1.0, 1e-3, -2e-3, 1.0, 0.0, 0.0, 0.5, 0.0, 0.0};
  std::vector<double> b = unit::product(K, x);
  b[0] += 4.0;
  b[1] -= 0.1;
  const std::vector<double> F = residual(K, b, x, 2);
  const double c = (K(1, 1) + K(2, 2)) / 2;
  EXPECT_NEAR(F[1], c * 1e-3, 1e-12);
  EXPECT_NEAR(F[2], c * -2e-3, 1e-12);
}

TEST(Friction, JacobianIsTheDerivative2D) { expect_jacobian_is_derivative(1); }

TEST(Friction, JacobianIsTheDerivative3D) { expect_jacobian_is_derivative(2); }
