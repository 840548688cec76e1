// The componentwise backward error of a linear solve (Oettli and Prager,
// 1964): the smallest relative change of the entries of A and b that x
// solves exactly. Unlike ||b - A x|| / ||b||, it stays at the round-off for
// a good factorisation of a system whose rows lie 1e22 apart (the Darcy
// rows mu_f/k against the mass balances), where a package that pivots by
// magnitude alone leaves it at 1 (docs/theory.md, "What a solve is trusted on").
#pragma once

#include <petscmat.h>

namespace biotcontact
{

/// y = |A| |x|, the magnitudes of A's entries times those of x's: |A| on
/// A's own rows (no communication), then one product, which gathers the
/// ghost entries of |x| as for A x (collective). The round-off bound of a
/// contact solve's residual takes it too (contact/convergence.h).
void absolute_product(Mat A, Vec x, Vec y);

/// max_i |r_i| / (|A| |x| + |b|)_i with r = b - A x, left in r; a row whose
/// denominator is 0 has r_i = 0 and counts 0 (collective).
double backward_error(Mat A, Vec x, Vec b, Vec r);

/// The backward error a factorisation's solve must reach: one step of
/// iterative refinement leaves a backward stable LU at 1e-16-1e-15; the
/// factorisations measured left 5e-16 to 4e-8 before it, 1 where they
/// solved wrongly.
constexpr double backward_error_tolerance = 1e-12;

/// The steps of iterative refinement (x += A^-1 r by the same factors)
/// tried before a solve is declared failed.
constexpr int refinement_steps = 3;

} // namespace biotcontact
