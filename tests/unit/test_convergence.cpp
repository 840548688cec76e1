// Unit tests of the contact solve's stopping rules (cpp/contact/convergence.h):
// the round-off bound of a residual W (K y - b) is eps (W |K| |y| + |b|)
// row by row, whatever the signs of K, y and b. The prototype's twin is
// tests/unit/test_convergence.py.
#include "contact/convergence.h"
#include "dense.h"

#include <gtest/gtest.h>

using namespace biotcontact;
using namespace unit;

namespace
{
/// spd_matrix(5) with the signs of its off-diagonal entries alternating.
Dense signed_matrix()
{
  Dense A = spd_matrix(5);
  for (int i = 0; i < 5; ++i)
    for (int j = 0; j < 5; ++j)
      if ((i + j) % 2 == 1)
        A(i, j) = -A(i, j);
  return A;
}
} // namespace

TEST(Convergence, RoundOffIsEpsTimesTheMagnitudes)
{
  const Dense A = signed_matrix();
  const std::vector<double> y{1.0, -2.0, 3.0, -4.0, 5.0}, b{-1e3, 0.0, 2e3, -3e3, 0.0}, w{1.0, 2.0, 0.5, 1.0, 4.0};
  Mat K = petsc_matrix(A);
  Vec Y = petsc_vector(K, y), B = petsc_vector(K, b), W = petsc_vector(K, w), r = petsc_vector(K, y);
  for (Vec weights : {Vec(nullptr), W})
  {
    residual_round_off(K, weights, Y, B, r);
    const std::vector<double> R = values(r);
    for (int i = 0; i < 5; ++i)
    {
      double sum = 0;
      for (int j = 0; j < 5; ++j)
        sum += std::abs(A(i, j)) * std::abs(y[j]);
      const double expected = PETSC_MACHINE_EPSILON * ((weights ? w[i] : 1.0) * sum + std::abs(b[i]));
      EXPECT_NEAR(R[i], expected, 1e-14 * expected) << "row " << i;
    }
  }
  EXPECT_EQ(values(Y), y); // y and b are left as they were
  EXPECT_EQ(values(B), b);
  for (Vec* v : {&Y, &B, &W, &r})
    VecDestroy(v);
  MatDestroy(&K);
}
