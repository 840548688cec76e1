// Row weights that balance the equations of a coupled system for a Krylov
// method: its residual norm adds forces (N) to volumes per second (m^3/s),
// and FGMRES minimises that sum, blind to a mass balance whose residual lies
// orders below the forces' round-off (docs/theory.md, "Balanced rows").
// Each field's rows are weighted by one constant, so a preconditioner that
// splits along the fields is left unchanged.
#pragma once

#include "solvers/field_split.h"

#include <petscmat.h>
#include <vector>

namespace biotcontact
{

/// The global rows of each field that is not split further (the fields'
/// leaves: the displacement, the flux, the pressure), owned by this rank.
std::vector<std::vector<PetscInt>> leaf_rows(const std::vector<Field>& fields, MPI_Comm comm);

/// weights[i] = m / m_f for each row i of the leaf f, where m_f is the
/// largest entry of the leaf's rows of A (in magnitude) and m the largest
/// of all leaves': every block's largest entry becomes A's largest; rows
/// of no leaf keep weight 1 (collective).
void set_balancing_weights(Mat A, const std::vector<std::vector<PetscInt>>& leaves, Vec weights);

/// @brief The Newton steps of K y = b solved as W K y = W b: the weights
/// W (set_balancing_weights), W b and W J for the Jacobian J (K, or
/// friction's). The same steps and active sets (W > 0 keeps every force's
/// sign); the Krylov method and the convergence tests see balanced rows.
class BalancedRows
{
public:
  /// For the system K split into `fields` (collective).
  BalancedRows(Mat K, const std::vector<Field>& fields, MPI_Comm comm);
  ~BalancedRows();
  BalancedRows(const BalancedRows&) = delete;
  BalancedRows& operator=(const BalancedRows&) = delete;

  /// K was reassembled: the next pose() takes the weights from it again.
  void operator_changed() { _stale = true; }
  /// Before a solve: the weights from K if it changed, W J, and W b.
  void pose(Mat K, Mat J, Vec b);
  /// W J after J changed within a solve (friction): an error code, for
  /// SNES's Jacobian callback.
  PetscErrorCode weigh_jacobian(Mat J);

  Vec weights() const { return _weights; }
  Vec load() const { return _load; }
  Mat jacobian() const { return _jacobian; }

private:
  std::vector<std::vector<PetscInt>> _leaves;
  Vec _weights = nullptr, _load = nullptr;
  Mat _jacobian = nullptr;
  bool _stale = true;
};

} // namespace biotcontact
