// Unit tests of the contact solve's stopping rules (cpp/contact/convergence.h):
// the round-off bound of a residual W (K y - b) is eps (W |K| |y| + |b|)
// row by row, whatever the signs of K, y and b; a solve's residual norms
// cycle when they alternate between two values; and a frictional solve whose
// forces are solved and whose separate rows jitter within their round-off,
// above atol, ends solved. The prototype's twin is
// tests/unit/test_convergence.py.
#include "contact/convergence.h"
#include "dense.h"

#include <array>
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

TEST(Convergence, NewtonCycleIsARepeatedCycleOfResiduals)
{
  // Phan's crack loaded at once on the coupled system: 1.0123e7 and
  // 1.0125e7 in turn after two steps that differ.
  std::vector<double> norms{1.8e9, 4.7e8};
  for (int k = 0; k < 6; ++k)
    norms.push_back(k % 2 == 0 ? 1.0123e7 : 1.0125e7);
  EXPECT_TRUE(newton_cycle(norms, 3));
  EXPECT_FALSE(newton_cycle(std::span(norms).first(7), 3)); // two periods and a half
  EXPECT_TRUE(newton_cycle(std::span(norms).first(6), 2));
  std::vector<double> near = norms; // the last differs in the 8th digit
  near.back() *= 1 + 1e-8;
  EXPECT_FALSE(newton_cycle(near, 3));
  const std::vector<double> steady(8, 1e7), falling{8, 7, 6, 5, 4, 3, 2, 1};
  EXPECT_FALSE(newton_cycle(steady, 3)); // stagnation is not a cycle
  EXPECT_FALSE(newton_cycle(falling, 3));
  EXPECT_FALSE(newton_cycle(std::vector<double>{}, 3));
  // Its cohesive crack opening along its whole length: four states.
  std::vector<double> four{4.1e7, 2.7e7};
  for (int k = 0; k < 12; ++k)
    four.push_back(std::array{2.9087e7, 2.6532e7, 2.6526e7, 2.9186e7}[k % 4]);
  EXPECT_TRUE(newton_cycle(four, 3));
  EXPECT_FALSE(newton_cycle(std::span(four).first(12), 3)); // two periods and a half
  // network3d's monolithic step at 0.5 m^3/s: nine states.
  std::vector<double> nine{5.4e10, 2.8e10};
  for (int k = 0; k < 27; ++k)
    nine.push_back(2.0e9 + 1e9 * (k % 9));
  EXPECT_TRUE(newton_cycle(nine, 3));
  EXPECT_FALSE(newton_cycle(std::span(nine).first(27), 3)); // two periods and a half
  std::vector<double> thirteen{1.0};                        // longer than longest_newton_cycle
  for (int k = 0; k < 39; ++k)
    thirteen.push_back(2.0 + k % 13);
  EXPECT_FALSE(newton_cycle(thirteen, 3));
}

TEST(Convergence, AClampedStartRejoinsTheAttemptAtItsFirstStep)
{
  // test_cohesive_opening's onset on the coupled system: the first attempt
  // from the last solution, the clamped start from every pair stuck, both
  // landing on 2.745445253772e7 after one step.
  const std::vector<double> attempt{7.283e-4, 2.745445253772e7, 2.768804085196e7, 2.535540936328e7};
  const std::vector<double> clamped{4.094618846568e7, 2.745445253772e7};
  EXPECT_TRUE(rejoins_attempt(clamped, attempt));
  std::vector<double> other = clamped; // another iterate
  other.back() *= 1 + 1e-8;
  EXPECT_FALSE(rejoins_attempt(other, attempt));
  EXPECT_FALSE(rejoins_attempt(std::span(clamped).first(1), attempt)); // no step yet
  std::vector<double> later = clamped; // decided at the first step only
  later.push_back(attempt[2]);
  EXPECT_FALSE(rejoins_attempt(later, attempt));
  EXPECT_FALSE(rejoins_attempt(clamped, std::span(attempt).first(1))); // the attempt took no step
  EXPECT_FALSE(rejoins_attempt(clamped, std::vector<double>{}));
}

TEST(Convergence, NewtonStallIsEveryStepBelowItsFraction)
{
  // The 50-fracture network's initial equilibrium on 2 ranks (bench/network.py
  // at size 0.5): its line search shrank the first steps to 1e-11 and 1e-7.
  const std::vector<double> network{2.995830435789e9, 2.995830435731e9, 2.995830249459e9, 2.995829726679e9,
                                    2.994522346468e9};
  EXPECT_FALSE(newton_stall(std::span(network).first(3), 3)); // two steps
  EXPECT_TRUE(newton_stall(std::span(network).first(4), 3));
  EXPECT_TRUE(newton_stall(network, 3)); // the 4th step: 4.4e-4
  // One step of 0.1 % among the last three is progress.
  std::vector<double> progress = network;
  progress.push_back(progress.back() * (1 - 1.01 * stall_reduction));
  EXPECT_FALSE(newton_stall(progress, 3));
  const std::vector<double> falling{8, 7, 6, 5}, rising{1, 2, 3, 4}, steady(4, 1e7);
  EXPECT_FALSE(newton_stall(falling, 3));
  EXPECT_TRUE(newton_stall(rising, 3)); // a step that raised it reduced it by less
  EXPECT_TRUE(newton_stall(steady, 3));
  EXPECT_FALSE(newton_stall(std::vector<double>{}, 3));
  EXPECT_FALSE(newton_stall(steady, 0));
}

namespace
{
/// F(x) = x - b whose separate row (the last) keeps a residual of
/// +-`jitter` that no step removes: a mass balance at its round-off.
struct Jittery
{
  Vec b;
  double jitter;
  int calls = 0;
};

PetscErrorCode jittery_residual(SNES, Vec x, Vec F, void* context)
{
  auto* j = static_cast<Jittery*>(context);
  PetscCall(VecWAXPY(F, -1.0, j->b, x));
  PetscCall(VecSetValue(F, 2, (j->calls++ % 2 == 0 ? 1.0 : -1.0) * j->jitter, ADD_VALUES));
  PetscCall(VecAssemblyBegin(F));
  PetscCall(VecAssemblyEnd(F));
  return 0;
}

PetscErrorCode fixed_jacobian(SNES, Vec, Mat, Mat, void*) { return 0; }

/// The reason a frictional solve of F (jittery_residual, J = I, no bounds)
/// ends with, its round-off measured on diag(1, 1, 1e18): the separate
/// row's is eps 1e18 |y_2| = 222 at y_2 = 1, above its jitter 50, which lies
/// above atol (1e-12 of the load, 0.14) and the relative target (rtol
/// 1e-10 of the first residual, 14).
SNESConvergedReason jittery_solve()
{
  Dense I(3), R(3);
  for (int i = 0; i < 3; ++i)
    I(i, i) = 1.0, R(i, i) = i == 2 ? 1e18 : 1.0;
  Mat J = petsc_matrix(I), K = petsc_matrix(R);
  Vec b = petsc_vector(J, {1e11, 1e11, 1.0}), x = petsc_vector(J, {0, 0, 0});
  Vec lower = petsc_vector(J, {PETSC_NINFINITY, PETSC_NINFINITY, PETSC_NINFINITY});
  Vec upper = petsc_vector(J, {PETSC_INFINITY, PETSC_INFINITY, PETSC_INFINITY});
  Jittery jittery{b, 50.0};
  SNES snes;
  SNESCreate(PETSC_COMM_WORLD, &snes);
  SNESSetType(snes, SNESVINEWTONRSLS);
  SNESSetFunction(snes, nullptr, jittery_residual, &jittery);
  SNESSetJacobian(snes, J, J, fixed_jacobian, nullptr);
  SNESVISetVariableBounds(snes, lower, upper);
  SNESSetTolerances(snes, 1e-12 * std::sqrt(2.0) * 1e11, 1e-10, 1e-12, 20, PETSC_DEFAULT);
  SNESLineSearch search;
  SNESGetLineSearch(snes, &search);
  SNESLineSearchSetType(search, SNESLINESEARCHBASIC);
  KSP ksp;
  SNESGetKSP(snes, &ksp);
  KSPSetType(ksp, KSPPREONLY);
  ContactConvergence convergence(PETSC_COMM_WORLD, {lower, upper, {}}, {2});
  convergence.attach(snes, b, true);
  convergence.measure_round_off(K, nullptr);
  convergence.pose();
  SNESSolve(snes, nullptr, x);
  SNESConvergedReason reason;
  SNESGetConvergedReason(snes, &reason);
  SNESDestroy(&snes);
  for (Vec* v : {&b, &x, &lower, &upper})
    VecDestroy(v);
  MatDestroy(&J), MatDestroy(&K);
  return reason;
}
} // namespace

TEST(Convergence, TheForceTestsLeaveOutTheSeparateRows)
{
  // The forces solved at the first step, the separate row within its
  // round-off: solved, though SNES's norm (50) stays above atol (network3d's
  // monolithic step, 100 Newton steps at 55-70 N against atol 53).
  EXPECT_EQ(jittery_solve(), SNES_CONVERGED_FNORM_ABS);
}
