// Unknowns tied in pairs, x_j = s x_i, eliminated from A x = b.
//
// The ties are linear constraints C x = 0, one row e_j - s e_i per tie.
// Their null space is spanned by the columns of
//     P = I + sum_k s_k e_{j_k} e_{i_k}^T    (x = P y, y_j = 0),
// so the constrained problem is the congruent system
//     A' y = b',   A' = P^T A P with rows and columns j made identity rows,
//                  b' = P^T b with b'_j = 0,
// and x = P y (the null-space method). A' is symmetric when A is. Each j is
// tied once and is no i: the ties are disjoint. The constraint's multiplier
// mu_k, with A x - b + C^T mu = 0, is -(A x - b)_j (for a fault: Tie).
#pragma once

#include <petscmat.h>
#include <vector>

namespace biotcontact
{

/// @brief One tie x_j = s x_i, by global indices (i and j may be owned by
/// two ranks). The RT0 flux ties of a transparent fault
/// (boundary_conditions.h) make its multiplier -(A x - b)_j the fault's
/// pressure trace times the facet flux of the j basis function.
struct Tie
{
  PetscInt i, j;
  double s;
};

/// @brief The elimination of tied unknowns from systems like A (vectors
/// like A's columns).
class TiedDofs
{
public:
  /// P from the ties whose j this rank owns (collective).
  TiedDofs(Mat A, const std::vector<Tie>& ties);
  ~TiedDofs();
  TiedDofs(const TiedDofs&) = delete;
  TiedDofs& operator=(const TiedDofs&) = delete;

  /// A' = P^T A P, rows and columns j identity (collective); reuses A''s
  /// structure when *At is already made.
  void reduce(Mat A, Mat* At) const;
  /// b' = P^T b, b'_j = 0.
  void load(Vec b, Vec bt) const;
  /// y from an x that satisfies the ties: x with y_j = 0 (a solve's guess).
  void guess(Vec x, Vec y) const;
  /// x = P y.
  void expand(Vec y, Vec x) const;
  /// The ties' global number (every rank).
  PetscInt size() const { return _size; }

private:
  Mat _P = nullptr;
  std::vector<PetscInt> _j; // this rank's j, global
  PetscInt _size = 0;
};

} // namespace biotcontact
