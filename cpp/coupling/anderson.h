// Anderson acceleration of the fixed-stress iteration (coupling.acceleration
// = "anderson"; beyond the paper, docs/theory.md, "Anderson acceleration").
//
// The split is a fixed-point iteration x^{n+1} = G(x^n) on the state of a
// window, x = (p^1, ..., p^q, u): the flow pass reads the pressures of the
// previous iterate and u, the mechanics returns the new u. G contracts at
// rate gamma in the norm of Theorems 1 and 2. Anderson's method (type II,
// Walker and Ni 2011) keeps the last m residuals f_j = G(x_j) - x_j, takes
//     x^{n+1} = G(x_n) - sum_j c_j (G(x_j) - G(x_{j-1})),
//     c = argmin || f_n - sum_j c_j (f_j - f_{j-1}) ||,
// the combination of the last m map values with the smallest linearised
// residual, and has G's fixed points, so the converged state is the split's.
#pragma once

#include <cstdint>
#include <deque>
#include <mpi.h>
#include <vector>

namespace biotcontact
{

/// A state: one array per block (ghost entries included; only the first
/// owned[b] entries of block b enter the inner products).
using State = std::vector<std::vector<double>>;

/// After this many restarts (each a change of the map: the split restarts
/// at each change of the contact set, in each window anew) Anderson gives
/// up, and the caller goes on with the plain iteration: an extrapolation
/// that keeps changing the map, measured opening and closing a fault's
/// pairs in turn through an injection's opening.
constexpr int anderson_restarts = 8;

class AndersonAcceleration
{
public:
  /// `depth` m >= 1 differences; per block its owned entries and weight
  /// (the inverse of the block's size, the scale of the stopping test, so
  /// that pressures in Pa and displacements in m count alike).
  AndersonAcceleration(MPI_Comm comm, int depth, std::vector<std::int32_t> owned, std::vector<double> weights);

  /// Forgets the history: the map changed (a new contact active set makes
  /// G another affine map, whose differences the old ones do not describe).
  /// Whether to go on: false after more than anderson_restarts restarts.
  bool restart();

  /// The next iterate from x and g = G(x); x is overwritten with it.
  void next(State& x, const State& g);

private:
  double dot(const State& a, const State& b) const;
  MPI_Comm _comm;
  int _depth;
  std::vector<std::int32_t> _owned;
  std::vector<double> _weights;
  // The last residual and map value, the last `depth` differences of
  // consecutive ones (oldest first) and the Gram matrix of the residual
  // differences, updated by one row per iteration.
  State _f, _g;
  std::deque<State> _dF, _dG;
  std::deque<std::deque<double>> _gram;
  int _restarts = 0;
};

} // namespace biotcontact
