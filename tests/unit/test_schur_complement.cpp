// Unit tests of the static condensation onto the contact DOFs
// (cpp/contact/schur_complement.h) on a small full SPD matrix built here:
// H = A_CC - A_CI A_II^{-1} A_IC and g = b_C - A_CI A_II^{-1} b_I as the
// dense formulas give them, H symmetric positive definite, the condensed
// problem solved by the full one's x_C, the extension solving the equations
// of I, H formed anew from A's current values, and the same H by MUMPS's
// partial factorisation (SPD A) and by columns. The prototype's twin is
// tests/unit/test_schur_complement.py.
#include "contact/schur_complement.h"
#include "dense.h"

#include <gtest/gtest.h>

using namespace biotcontact;

namespace
{
struct Schur : testing::Test
{
  const int n = 10;
  const std::vector<int> contact{1, 4, 6, 9}, interior{0, 2, 3, 5, 7, 8};
  const std::vector<double> b_values{1, -2, 0.5, 3, -1, 0.25, 2, -4, 1.5, -0.75};
  unit::Dense A = unit::spd_matrix(n);
  Mat petsc_A = nullptr;
  std::unique_ptr<SchurComplement> schur;

  void SetUp() override
  {
    set_solver_defaults("schur_test_", Structure::spd, {Method::direct, "unit test"}, PETSC_COMM_WORLD);
    petsc_A = unit::petsc_matrix(A);
    schur = std::make_unique<SchurComplement>(PETSC_COMM_WORLD, "schur_test_", petsc_A, Structure::spd,
                                              std::vector<std::int32_t>(contact.begin(), contact.end()));
    schur->assemble();
  }
  void TearDown() override
  {
    schur.reset();
    MatDestroy(&petsc_A);
  }
  /// A_II and the columns of A_I(cols).
  unit::Dense interior_block() const
  {
    unit::Dense Aii(static_cast<int>(interior.size()));
    for (std::size_t i = 0; i < interior.size(); ++i)
      for (std::size_t j = 0; j < interior.size(); ++j)
        Aii(i, j) = A(interior[i], interior[j]);
    return Aii;
  }
  std::vector<double> interior_column(int col) const
  {
    std::vector<double> c;
    for (int i : interior)
      c.push_back(A(i, col));
    return c;
  }
  /// A_CI v for v on I.
  double contact_row_times(int row, const std::vector<double>& v) const
  {
    double s = 0;
    for (std::size_t k = 0; k < interior.size(); ++k)
      s += A(row, interior[k]) * v[k];
    return s;
  }
  /// A seq vector of the contact DOFs (H's order) holding `values`.
  static Vec contact_vector(const std::vector<double>& values)
  {
    Vec v;
    VecCreateSeq(PETSC_COMM_SELF, static_cast<PetscInt>(values.size()), &v);
    PetscScalar* a = nullptr;
    VecGetArray(v, &a);
    std::copy(values.begin(), values.end(), a);
    VecRestoreArray(v, &a);
    return v;
  }
  double round_off() const { return 1e-14 * unit::largest(A.a); }
};
} // namespace

TEST_F(Schur, MatchesTheDenseFormula)
{
  ASSERT_EQ(schur->size(), 4);
  EXPECT_EQ(schur->offset(), 0);
  EXPECT_EQ(schur->columns, 4) << "one right-hand side per contact DOF";
  std::vector<std::vector<double>> A_ic;
  for (int c : contact)
    A_ic.push_back(interior_column(c));
  const auto X = unit::solve(interior_block(), A_ic); // A_II^{-1} A_IC
  const unit::Dense H = unit::dense(schur->matrix());
  for (std::size_t i = 0; i < contact.size(); ++i)
    for (std::size_t j = 0; j < contact.size(); ++j)
    {
      const double expected = A(contact[i], contact[j]) - contact_row_times(contact[i], X[j]);
      EXPECT_NEAR(H(i, j), expected, round_off()) << "entry " << i << ", " << j;
    }
}

TEST_F(Schur, IsSymmetricPositiveDefinite)
{
  // The Schur complement of an SPD matrix is SPD: Cholesky's pivots > 0.
  unit::Dense H = unit::dense(schur->matrix());
  for (int i = 0; i < H.n; ++i)
    for (int j = 0; j < H.n; ++j)
      EXPECT_NEAR(H(i, j), H(j, i), round_off()) << "entry " << i << ", " << j;
  for (int k = 0; k < H.n; ++k)
  {
    ASSERT_GT(H(k, k), 0) << "pivot " << k;
    for (int i = k + 1; i < H.n; ++i)
      for (int j = k + 1; j < H.n; ++j)
        H(i, j) -= H(i, k) * H(k, j) / H(k, k);
  }
}

TEST_F(Schur, CondensedLoadMatchesTheDenseFormula)
{
  Vec b = unit::petsc_vector(petsc_A, b_values), g = contact_vector(std::vector<double>(contact.size()));
  schur->condensed_load(b, g);
  std::vector<double> b_i;
  for (int i : interior)
    b_i.push_back(b_values[i]);
  const std::vector<double> v = unit::solve(interior_block(), {b_i})[0];
  const std::vector<double> got = unit::values(g);
  for (std::size_t k = 0; k < contact.size(); ++k)
    EXPECT_NEAR(got[k], b_values[contact[k]] - contact_row_times(contact[k], v), round_off()) << "DOF " << k;
  VecDestroy(&b);
  VecDestroy(&g);
}

TEST_F(Schur, CondensedProblemHasTheSameSolution)
{
  // x solves A x = b: y = x_C (restrict_to_contact) solves H y = g.
  const std::vector<double> x_values = unit::solve(A, {b_values})[0];
  Vec x = unit::petsc_vector(petsc_A, x_values), b = unit::petsc_vector(petsc_A, b_values);
  Vec y = contact_vector(std::vector<double>(contact.size())), g, r;
  VecDuplicate(y, &g);
  VecDuplicate(y, &r);
  schur->restrict_to_contact(x, y);
  schur->condensed_load(b, g);
  const std::vector<double> y_values = unit::values(y);
  for (std::size_t k = 0; k < contact.size(); ++k)
    EXPECT_EQ(y_values[k], x_values[contact[k]]) << "x_C, DOF " << k;
  MatMult(schur->matrix(), y, r);
  VecAXPY(r, -1.0, g);
  for (double residual : unit::values(r))
    EXPECT_NEAR(residual, 0.0, 1e-14 * unit::largest(b_values));
  for (Vec* v : {&x, &b, &y, &g, &r})
    VecDestroy(v);
}

TEST_F(Schur, ExtensionSolvesTheInteriorEquations)
{
  // x_C = y exactly, and the equations of I hold: (A x - b)_I = 0.
  const std::vector<double> y_values{1e-3, -2e-3, 0.5, 4};
  Vec b = unit::petsc_vector(petsc_A, b_values), y = contact_vector(y_values), x;
  VecDuplicate(b, &x);
  schur->extend(b, y, x);
  const std::vector<double> x_values = unit::values(x), Ax = unit::product(A, x_values);
  for (std::size_t k = 0; k < contact.size(); ++k)
    EXPECT_EQ(x_values[contact[k]], y_values[k]) << "DOF " << contact[k];
  for (int i : interior)
    EXPECT_NEAR(Ax[i] - b_values[i], 0.0, round_off() * unit::largest(x_values)) << "equation " << i;
  for (Vec* v : {&b, &y, &x})
    VecDestroy(v);
}

TEST_F(Schur, PartialFactorisationMatchesTheColumns)
{
  // From partial_factorisation_from contact DOFs on (an SPD A on one
  // rank), H comes from MUMPS's partial factorisation: the same H to
  // round-off, no right-hand side solved.
  SchurComplement partial(PETSC_COMM_WORLD, "schur_test_", petsc_A, Structure::spd,
                          std::vector<std::int32_t>(contact.begin(), contact.end()));
  partial.partial_factorisation_from = 0;
  partial.assemble();
  EXPECT_EQ(partial.factorizations, 1) << "one partial factorisation";
  EXPECT_EQ(partial.columns, 0);
  const unit::Dense H = unit::dense(schur->matrix()), G = unit::dense(partial.matrix());
  for (int i = 0; i < H.n; ++i)
    for (int j = 0; j < H.n; ++j)
      EXPECT_NEAR(G(i, j), H(i, j), 10 * round_off()) << "entry " << i << ", " << j;
}

TEST_F(Schur, ReassemblyFollowsTheValues)
{
  // assemble() forms H from A's current values: A doubled, H doubles.
  const unit::Dense before = unit::dense(schur->matrix());
  MatScale(petsc_A, 2.0);
  schur->assemble();
  EXPECT_EQ(schur->columns, 8) << "4 right-hand sides per formation";
  const unit::Dense after = unit::dense(schur->matrix());
  for (int i = 0; i < before.n; ++i)
    for (int j = 0; j < before.n; ++j)
      EXPECT_NEAR(after(i, j), 2 * before(i, j), 2 * round_off()) << "entry " << i << ", " << j;
}
