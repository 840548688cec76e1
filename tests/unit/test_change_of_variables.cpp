// Unit tests of the change of variables (cpp/contact/change_of_variables.h):
// T_node's rows are the normals completed orthonormally, so each Signorini
// constraint nu_j . u <= g_j is the bound w_j <= g_j on w = T u; dependent
// normals and a change that would mix a prescribed component are refused;
// a fault's pair block makes the jump and the mean the new variables;
// on a system, A' = T^{-T} A T^{-1} is the same energy and its residual
// holds the constraints' multipliers. The prototype's twin is
// tests/unit/test_change_of_variables.py.
#include "contact/change_of_variables.h"
#include "dense.h"

#include <cmath>
#include <gtest/gtest.h>

using namespace biotcontact;

namespace
{
const double pi = std::acos(-1.0);

std::array<double, 3> normalised(double x, double y, double z)
{
  const double length = std::sqrt(x * x + y * y + z * z);
  return {x / length, y / length, z / length};
}

double row_dot(const NodeMatrix& T, int row, const std::array<double, 3>& v, int d)
{
  double s = 0;
  for (int i = 0; i < d; ++i)
    s += T[d * row + i] * v[i];
  return s;
}

/// w = T u.
std::array<double, 3> apply(const NodeMatrix& T, const std::array<double, 3>& u, int d)
{
  std::array<double, 3> w{0, 0, 0};
  for (int r = 0; r < d; ++r)
    w[r] = row_dot(T, r, u, d);
  return w;
}

/// Whether the rows of T are orthonormal (T T^T = I) to round-off.
void expect_orthogonal(const NodeMatrix& T, int d)
{
  for (int r = 0; r < d; ++r)
    for (int s = 0; s < d; ++s)
    {
      std::array<double, 3> row{0, 0, 0};
      for (int i = 0; i < d; ++i)
        row[i] = T[d * s + i];
      EXPECT_NEAR(row_dot(T, r, row, d), r == s ? 1.0 : 0.0, 1e-15) << "rows " << r << ", " << s;
    }
}

const std::array<bool, 3> free_node{false, false, false};

/// Whether A B is the n x n identity to `tolerance`.
void expect_identity(const std::vector<double>& A, const std::vector<double>& B, int n, double tolerance)
{
  for (int r = 0; r < n; ++r)
    for (int c = 0; c < n; ++c)
    {
      double s = 0;
      for (int k = 0; k < n; ++k)
        s += A[n * r + k] * B[n * k + c];
      EXPECT_NEAR(s, r == c ? 1.0 : 0.0, tolerance) << n << " x " << n << ", entry " << r << ", " << c;
    }
}
} // namespace

TEST(ChangeOfVariables, OneFoundationIsARotation)
{
  // 2D, a foundation inclined at 30 degrees; 3D, a normal along no axis.
  const double angle = pi / 6;
  const std::array<double, 3> normal_2d{std::sin(angle), -std::cos(angle), 0};
  const std::array<double, 3> normal_3d = normalised(1, -2, 2);
  for (const auto& [normal, d] : {std::pair{normal_2d, 2}, std::pair{normal_3d, 3}})
  {
    const std::optional<NodeMatrix> T = node_change_of_variables({normal}, d, free_node);
    ASSERT_TRUE(T);
    for (int i = 0; i < d; ++i)
      EXPECT_EQ((*T)[i], normal[i]) << "the first row is the normal";
    expect_orthogonal(*T, d);
  }
}

TEST(ChangeOfVariables, InclinedFoundationBoundIsTheGap)
{
  // u . nu <= g is w_0 <= g: a node lying on the foundation (u = g nu plus
  // any tangential slip s tau) has w_0 = g, and the slip is all in w_1.
  const double angle = pi / 6, gap = 1.2e-3, round_off = 1e-14 * gap;
  const std::array<double, 3> nu{std::sin(angle), -std::cos(angle), 0}, tau{std::cos(angle), std::sin(angle), 0};
  const NodeMatrix T = node_change_of_variables({nu}, 2, free_node).value();
  for (double slip : {0.0, 1e-3, -5e-3})
  {
    const std::array<double, 3> on{gap * nu[0] + slip * tau[0], gap * nu[1] + slip * tau[1], 0};
    const std::array<double, 3> w = apply(T, on, 2);
    EXPECT_NEAR(w[0], gap, round_off) << "slip " << slip;
    EXPECT_NEAR(std::abs(w[1]), std::abs(slip), round_off) << "slip " << slip;
    // Half the gap closed: inside the bound by half the gap.
    const std::array<double, 3> inside{on[0] - gap / 2 * nu[0], on[1] - gap / 2 * nu[1], 0};
    EXPECT_NEAR(apply(T, inside, 2)[0], gap / 2, round_off);
  }
}

TEST(ChangeOfVariables, TwoFoundationsAtOneNode)
{
  // Two foundations 36.87 degrees apart meet at the node: the first two
  // rows are their normals (not orthogonal), the third the tangent they
  // share, and u = T^{-1} (g_1, g_2, s) touches both.
  const std::array<double, 3> n1{0, -1, 0}, n2{0.6, -0.8, 0};
  const NodeMatrix T = node_change_of_variables({n1, n2}, 3, free_node).value();
  for (int i = 0; i < 3; ++i)
  {
    EXPECT_EQ(T[i], n1[i]);
    EXPECT_EQ(T[3 + i], n2[i]);
  }
  const std::array<double, 3> tangent{T[6], T[7], T[8]};
  EXPECT_NEAR(row_dot(T, 2, tangent, 3), 1.0, 1e-15);
  EXPECT_NEAR(row_dot(T, 0, tangent, 3), 0.0, 1e-15);
  EXPECT_NEAR(row_dot(T, 1, tangent, 3), 0.0, 1e-15);
  const double g1 = 1e-3, g2 = 2e-3;
  const std::vector<double> inv = inverse(node_block(T, 3), 3);
  NodeMatrix T_inverse{};
  std::copy(inv.begin(), inv.end(), T_inverse.begin());
  const std::array<double, 3> corner = apply(T_inverse, {g1, g2, 0.7}, 3);
  EXPECT_NEAR(row_dot(T, 0, corner, 3), g1, 1e-15);
  EXPECT_NEAR(row_dot(T, 1, corner, 3), g2, 1e-15);

  // In 2D two foundations leave nothing to complete: T is their normals.
  const NodeMatrix T2 = node_change_of_variables({n1, n2}, 2, free_node).value();
  EXPECT_EQ(T2[0], n1[0]);
  EXPECT_EQ(T2[1], n1[1]);
  EXPECT_EQ(T2[2], n2[0]);
  EXPECT_EQ(T2[3], n2[1]);
}

TEST(ChangeOfVariables, DependentNormalsAreRefused)
{
  const std::array<double, 3> n = normalised(1, -3, 0);
  EXPECT_FALSE(node_change_of_variables({n, n}, 2, free_node)) << "the same normal twice";
  EXPECT_FALSE(node_change_of_variables({n, {-n[0], -n[1], 0}}, 2, free_node)) << "opposite normals";
  auto turned = [&](double angle)
  {
    return std::array<double, 3>{std::cos(angle) * n[0] - std::sin(angle) * n[1],
                                 std::sin(angle) * n[0] + std::cos(angle) * n[1], 0};
  };
  EXPECT_FALSE(node_change_of_variables({n, turned(1e-10)}, 2, free_node)) << "1e-10 rad apart";
  EXPECT_TRUE(node_change_of_variables({n, turned(1e-3)}, 2, free_node)) << "1e-3 rad apart";
  // Three normals in 3D, the third in the plane of the first two.
  const std::array<double, 3> a{0, 0, -1}, b{0.6, 0, -0.8}, c = normalised(0.3, 0, -0.9);
  EXPECT_FALSE(node_change_of_variables({a, b, c}, 3, free_node));
  EXPECT_TRUE(node_change_of_variables({a, b, normalised(0.3, 0.2, -0.9)}, 3, free_node));
}

TEST(ChangeOfVariables, PrescribedComponentIsKept)
{
  // A normal perpendicular to z at a node whose z is prescribed: z stays
  // one of the new variables (a row of T is e_z, and no other row mixes it).
  const std::array<double, 3> n{0.6, -0.8, 0};
  const std::optional<NodeMatrix> T = node_change_of_variables({n}, 3, {false, false, true});
  ASSERT_TRUE(T);
  int rows_with_z = 0;
  for (int r = 0; r < 3; ++r)
    if ((*T)[3 * r + 2] != 0)
    {
      ++rows_with_z;
      EXPECT_EQ(std::abs((*T)[3 * r + 2]), 1.0);
      EXPECT_EQ((*T)[3 * r], 0.0);
      EXPECT_EQ((*T)[3 * r + 1], 0.0);
    }
  EXPECT_EQ(rows_with_z, 1);
  // x prescribed, but the normal has an x part: the change would mix it.
  EXPECT_FALSE(node_change_of_variables({n}, 3, {true, false, false}));
  EXPECT_FALSE(node_change_of_variables({n}, 2, {true, false, false}));
  // The whole node prescribed: it does not move, any change will do.
  EXPECT_TRUE(node_change_of_variables({n}, 3, {true, true, true}));
}

TEST(ChangeOfVariables, CoordinateAxis)
{
  EXPECT_EQ(coordinate_axis({0, -1, 0}, 2), std::make_pair(1, -1));
  EXPECT_EQ(coordinate_axis({0, 0, 1}, 3), std::make_pair(2, 1));
  EXPECT_EQ(coordinate_axis({1e-15, -1, 0}, 2), std::make_pair(1, -1)) << "round-off";
  EXPECT_FALSE(coordinate_axis({0.6, -0.8, 0}, 2));
  EXPECT_FALSE(coordinate_axis({1e-13, -1, 0}, 2)) << "more than round-off";
  // A normal along z is no axis of a 2D problem.
  EXPECT_FALSE(coordinate_axis({0, 0, 1}, 2));
}

TEST(ChangeOfVariables, InverseIsTheInverse)
{
  const std::vector<double> T2{2, 1, -0.5, 3}, T3{2, 1, 0, -1, 3, 0.5, 0.25, -2, 4};
  // A pivot of 0 on the diagonal: elimination must exchange rows.
  const std::vector<double> T4{0, 1, 0, 0, 1, 0, 0, 2, 0, 0, 3, 1, 0.5, 0, 0, 3};
  for (const auto& [T, n] : {std::pair{T2, 2}, std::pair{T3, 3}, std::pair{T4, 4}})
    expect_identity(T, inverse(T, n), n, 1e-15);
}

TEST(ChangeOfVariables, PairBlockIsJumpAndMean)
{
  // A fault inclined at 30 degrees in 3D: w_J = R (u+ - u-) with R's first
  // row the constraint normal nu = -n, w_M = (u+ + u-) / 2; the inverse is
  // u+- = w_M +- R^T w_J / 2.
  const int d = 3, n = 2 * d;
  const std::array<double, 3> nu = normalised(std::sin(pi / 6), 0, -std::cos(pi / 6));
  const NodeMatrix R = node_change_of_variables({nu}, d, free_node).value();
  const std::vector<double> B = pair_change_of_variables(R, d), B_inverse = inverse(B, n);
  const std::array<double, 6> u{1e-3, -2e-3, 0.5e-3, 0.7e-3, -1e-3, 3e-3};
  std::array<double, 3> jump{}, mean{};
  for (int i = 0; i < d; ++i)
  {
    jump[i] = u[i] - u[d + i];
    mean[i] = (u[i] + u[d + i]) / 2;
  }
  const std::array<double, 3> w_J = apply(R, jump, d);
  for (int r = 0; r < n; ++r)
  {
    double w = 0;
    for (int c = 0; c < n; ++c)
      w += B[n * r + c] * u[c];
    EXPECT_NEAR(w, r < d ? w_J[r] : mean[r - d], 1e-18) << "row " << r;
  }
  EXPECT_NEAR(w_J[0], row_dot(R, 0, jump, d), 1e-18);
  EXPECT_NEAR(w_J[0], nu[0] * jump[0] + nu[1] * jump[1] + nu[2] * jump[2], 1e-18) << "the bounded jump is nu.[u]";
  for (int r = 0; r < d; ++r)
    for (int c = 0; c < d; ++c)
    {
      const double half_R_T = R[d * c + r] / 2, identity = r == c ? 1.0 : 0.0;
      EXPECT_NEAR(B_inverse[n * r + c], half_R_T, 1e-15);
      EXPECT_NEAR(B_inverse[n * r + d + c], identity, 1e-15);
      EXPECT_NEAR(B_inverse[n * (d + r) + c], -half_R_T, 1e-15);
      EXPECT_NEAR(B_inverse[n * (d + r) + d + c], identity, 1e-15);
    }
}

namespace
{
/// A system of 6 nodes in 2D (12 DOFs) with two transformed nodes and a
/// fault's node pair: node 0 on a foundation inclined at 30 degrees, node 2
/// on two foundations, nodes 3 (+) and 5 (-) the two faces of a fault
namespace
{
/// An X junction in 2D: pieces 0 and 1 above fault A (normal nA into
/// them), 2 and 3 below; B (normal nB) has 1 and 3 on its + side. Its four
/// pairs: A's arms (+0, -2), (+1, -3), B's arms (+1, -0), (+3, -2), piece 1
/// on the + side of two (rows 0 and 1).
std::vector<JunctionPair> x_junction()
{
  const std::array<double, 3> nA = normalised(-std::sin(pi / 6), std::cos(pi / 6), 0);
  const std::array<double, 3> nB = normalised(std::cos(pi / 9), std::sin(pi / 9), 0);
  const auto nu = [](const std::array<double, 3>& n) { return std::array<double, 3>{-n[0], -n[1], -n[2]}; };
  return {{0, 2, 0, nu(nA)}, {1, 3, 0, nu(nA)}, {1, 0, 1, nu(nB)}, {3, 2, 0, nu(nB)}};
}
} // namespace

TEST(ChangeOfVariables, JunctionRowsAreTheNormalJumps)
{
  // Each pair's row of w = B u is nu . (u+ - u-); the other rows are
  // orthonormal and orthogonal to those; B is invertible.
  const int d = 2, m = 4, n = m * d;
  const std::vector<JunctionPair> pairs = x_junction();
  const std::vector<double> B = junction_change_of_variables(pairs, m, d, std::vector<char>(n, 0)).value();
  const std::vector<double> u{1e-3, -2e-3, 0.5e-3, 0.7e-3, -1e-3, 3e-3, 2e-3, -0.4e-3};
  std::vector<char> constraint(n, 0);
  for (const JunctionPair& p : pairs)
  {
    const int row = d * p.plus + p.row;
    constraint[row] = 1;
    double w = 0, expected = 0;
    for (int c = 0; c < n; ++c)
      w += B[n * row + c] * u[c];
    for (int i = 0; i < d; ++i)
      expected += p.normal[i] * (u[d * p.plus + i] - u[d * p.minus + i]);
    EXPECT_NEAR(w, expected, 1e-18) << "row " << row;
  }
  for (int r = 0; r < n; ++r)
    for (int s = 0; s < n; ++s)
    {
      if (constraint[r] and constraint[s])
        continue;
      double dot = 0;
      for (int c = 0; c < n; ++c)
        dot += B[n * r + c] * B[n * s + c];
      EXPECT_NEAR(dot, r == s ? 1.0 : 0.0, 1e-14) << "rows " << r << ", " << s;
    }
  expect_identity(inverse(B, n), B, n, 1e-12);
}

TEST(ChangeOfVariables, JunctionOfDependentConstraintsIsRefused)
{
  // The same constraint twice (in another row), or two pairs in one row.
  std::vector<JunctionPair> pairs = x_junction();
  pairs.push_back(pairs[0]);
  pairs.back().plus = 0, pairs.back().row = 1;
  const std::vector<char> none(8, 0);
  EXPECT_FALSE(junction_change_of_variables(pairs, 4, 2, none));
  pairs = x_junction();
  pairs[2].row = 0;
  EXPECT_FALSE(junction_change_of_variables(pairs, 4, 2, none));
}

TEST(ChangeOfVariables, JunctionKeepsPrescribedComponents)
{
  // Two vertical planes crossing in 3D (the X of x_junction in the x-y
  // plane) on a boundary whose z is held: each node's z row is its unit
  // vector, and no other row reaches a z DOF, so the Dirichlet rows stay
  // their own; holding an x as well (along a normal) is refused.
  const int d = 3, m = 4, n = m * d;
  std::vector<char> held(n, 0);
  for (int v = 0; v < m; ++v)
    held[d * v + 2] = 1;
  const std::vector<double> B = junction_change_of_variables(x_junction(), m, d, held).value();
  for (int r = 0; r < n; ++r)
    for (int v = 0; v < m; ++v)
      EXPECT_EQ(B[n * r + d * v + 2], r == d * v + 2 ? 1.0 : 0.0) << "row " << r << ", node " << v;
  expect_identity(inverse(B, n), B, n, 1e-12);
  held[0] = 1;
  EXPECT_FALSE(junction_change_of_variables(x_junction(), m, d, held));
}

/// inclined at 60 degrees.
struct ChangeOfVariablesSystem : testing::Test
{
  static constexpr int d = 2, size = 12;
  unit::Dense A = unit::spd_matrix(size), T{size};
  std::vector<ChangeOfVariables::Block> blocks;
  Mat petsc_A = nullptr, At = nullptr;
  std::unique_ptr<ChangeOfVariables> change;

  void SetUp() override
  {
    const double angle = pi / 6;
    const std::array<double, 3> inclined{std::sin(angle), -std::cos(angle), 0}, fault{-std::cos(angle), -std::sin(angle), 0};
    blocks.push_back({{0, 1}, node_block(node_change_of_variables({inclined}, d, free_node).value(), d)});
    blocks.push_back({{4, 5}, node_block(node_change_of_variables({{0, -1, 0}, {0.6, -0.8, 0}}, d, free_node).value(), d)});
    blocks.push_back({{6, 7, 10, 11}, pair_change_of_variables(node_change_of_variables({fault}, d, free_node).value(), d)});
    for (int i = 0; i < size; ++i)
      T(i, i) = 1;
    for (const auto& block : blocks)
    {
      const int k = static_cast<int>(block.dofs.size());
      for (int r = 0; r < k; ++r)
        for (int c = 0; c < k; ++c)
          T(block.dofs[r], block.dofs[c]) = block.T[k * r + c];
    }
    petsc_A = unit::petsc_matrix(A);
    change = std::make_unique<ChangeOfVariables>(petsc_A, blocks, true);
    change->congruence(petsc_A, &At);
  }
  void TearDown() override
  {
    change.reset();
    MatDestroy(&At);
    MatDestroy(&petsc_A);
  }
  /// T^{-1}, dense, from the blocks' inverses.
  unit::Dense inverse_T() const
  {
    unit::Dense inv(size);
    for (int i = 0; i < size; ++i)
      inv(i, i) = 1;
    for (const auto& block : blocks)
    {
      const int k = static_cast<int>(block.dofs.size());
      const std::vector<double> B = inverse(block.T, k);
      for (int r = 0; r < k; ++r)
        for (int c = 0; c < k; ++c)
          inv(block.dofs[r], block.dofs[c]) = B[k * r + c];
    }
    return inv;
  }
};

const std::vector<double> x_values{1e-3, -2e-3, 0.5e-3, 0.7e-3, -1e-3, 3e-3, 2e-3, -0.4e-3, 1.5e-3, 0.2e-3, -0.8e-3, 0.9e-3};
const std::vector<double> b_values{1, -2, 0.5, 3, -1, 0.25, 2, -4, 1.5, -0.5, 0.75, 2.5};
} // namespace

TEST_F(ChangeOfVariablesSystem, CongruenceIsTheSameEnergy)
{
  // A' = T^{-T} A T^{-1}, symmetric, and x'^T A' x' = x^T A x for x' = T x.
  const unit::Dense inv = inverse_T(), expected = unit::product(unit::transpose(inv), unit::product(A, inv));
  const unit::Dense got = unit::dense(At);
  const double round_off = 1e-14 * unit::largest(A.a);
  for (int i = 0; i < size; ++i)
    for (int j = 0; j < size; ++j)
    {
      EXPECT_NEAR(got(i, j), expected(i, j), round_off) << "entry " << i << ", " << j;
      EXPECT_NEAR(got(i, j), got(j, i), round_off) << "symmetry " << i << ", " << j;
    }
  Vec x = unit::petsc_vector(petsc_A, x_values), xt, back;
  VecDuplicate(x, &xt);
  VecDuplicate(x, &back);
  change->forward(x, xt);
  change->backward(xt, back);
  const std::vector<double> w = unit::values(xt), returned = unit::values(back);
  const std::vector<double> Tx = unit::product(T, x_values);
  double energy = 0, energy_t = 0;
  const std::vector<double> Ax = unit::product(A, x_values), Atw = unit::product(got, w);
  for (int i = 0; i < size; ++i)
  {
    EXPECT_NEAR(w[i], Tx[i], 1e-18) << "forward, DOF " << i;
    EXPECT_NEAR(returned[i], x_values[i], 1e-18) << "backward, DOF " << i;
    energy += x_values[i] * Ax[i];
    energy_t += w[i] * Atw[i];
  }
  EXPECT_NEAR(energy_t, energy, 1e-14 * energy);
  for (Vec* v : {&x, &xt, &back})
    VecDestroy(v);
}

TEST_F(ChangeOfVariablesSystem, ResidualHoldsTheMultipliers)
{
  // F' = A' x' - b' with b' = T^{-T} b: in a block's DOFs F = T^T F' =
  // sum_j F'_j (row j of T), elsewhere F' = F.
  Vec x = unit::petsc_vector(petsc_A, x_values), b = unit::petsc_vector(petsc_A, b_values), xt, bt, Ft;
  for (Vec* v : {&xt, &bt, &Ft})
    VecDuplicate(x, v);
  change->forward(x, xt);
  change->dual(b, bt);
  MatMult(At, xt, Ft);
  VecAXPY(Ft, -1.0, bt);
  const std::vector<double> F_t = unit::values(Ft), Ax = unit::product(A, x_values);
  std::vector<double> F(size), TtFt(F_t);
  for (int i = 0; i < size; ++i)
    F[i] = Ax[i] - b_values[i];
  for (const auto& block : blocks)
  {
    const int k = static_cast<int>(block.dofs.size());
    for (int i = 0; i < k; ++i)
    {
      TtFt[block.dofs[i]] = 0;
      for (int j = 0; j < k; ++j)
        TtFt[block.dofs[i]] += F_t[block.dofs[j]] * block.T[k * j + i];
    }
  }
  for (int i = 0; i < size; ++i)
    EXPECT_NEAR(TtFt[i], F[i], 1e-14 * unit::largest(b_values)) << "DOF " << i;
  for (Vec* v : {&x, &b, &xt, &bt, &Ft})
    VecDestroy(v);
}
