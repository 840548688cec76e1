#include "solvers/row_weights.h"

#include "assembly/petsc_error.h"

#include <algorithm>
#include <cmath>
#include <functional>

namespace biotcontact
{

std::vector<std::vector<PetscInt>> leaf_rows(const std::vector<Field>& fields, MPI_Comm comm)
{
  std::vector<std::vector<PetscInt>> leaves;
  // `to_global` maps a row of the enclosing block to a row of the system.
  std::function<void(const Field&, const std::function<PetscInt(PetscInt)>&)> visit
      = [&](const Field& f, const std::function<PetscInt(PetscInt)>& to_global)
  {
    if (f.fields.empty())
    {
      std::vector<PetscInt> rows(f.dofs.size());
      std::transform(f.dofs.begin(), f.dofs.end(), rows.begin(), to_global);
      leaves.push_back(std::move(rows));
      return;
    }
    const PetscInt offset = block_offset(f, comm);
    for (const Field& part : f.fields)
      visit(part, [&](PetscInt row) { return to_global(f.dofs[row - offset]); });
  };
  for (const Field& f : fields)
    visit(f, [](PetscInt row) { return row; });
  return leaves;
}

void set_balancing_weights(Mat A, const std::vector<std::vector<PetscInt>>& leaves, Vec weights)
{
  const std::string what = "the balancing weights: ";
  check_petsc(MatGetRowMaxAbs(A, weights, nullptr), what + "MatGetRowMaxAbs");
  PetscInt start = 0;
  check_petsc(VecGetOwnershipRange(weights, &start, nullptr), what + "VecGetOwnershipRange");
  PetscScalar* w = nullptr;
  check_petsc(VecGetArray(weights, &w), what + "VecGetArray");
  std::vector<double> largest(leaves.size(), 0.0);
  for (std::size_t f = 0; f < leaves.size(); ++f)
    for (PetscInt row : leaves[f])
      largest[f] = std::max(largest[f], std::abs(w[row - start]));
  MPI_Comm comm = MPI_COMM_NULL;
  check_petsc(PetscObjectGetComm(reinterpret_cast<PetscObject>(A), &comm), what + "PetscObjectGetComm");
  MPI_Allreduce(MPI_IN_PLACE, largest.data(), static_cast<int>(largest.size()), MPI_DOUBLE, MPI_MAX, comm);
  const double m = *std::max_element(largest.begin(), largest.end());
  PetscInt n = 0;
  check_petsc(VecGetLocalSize(weights, &n), what + "VecGetLocalSize");
  std::fill(w, w + n, 1.0);
  for (std::size_t f = 0; f < leaves.size(); ++f)
    for (PetscInt row : leaves[f])
      w[row - start] = largest[f] > 0 ? m / largest[f] : 1.0;
  check_petsc(VecRestoreArray(weights, &w), what + "VecRestoreArray");
}

BalancedRows::BalancedRows(Mat K, const std::vector<Field>& fields, MPI_Comm comm) : _leaves(leaf_rows(fields, comm))
{
  check_petsc(MatCreateVecs(K, &_weights, &_load), "the balanced rows: MatCreateVecs");
  check_petsc(MatDuplicate(K, MAT_COPY_VALUES, &_jacobian), "the balanced rows: MatDuplicate");
}

BalancedRows::~BalancedRows()
{
  warn_petsc(VecDestroy(&_weights), "the balanced rows: VecDestroy");
  warn_petsc(VecDestroy(&_load), "the balanced rows: VecDestroy");
  warn_petsc(MatDestroy(&_jacobian), "the balanced rows: MatDestroy");
}

void BalancedRows::pose(Mat K, Mat J, Vec b)
{
  if (_stale)
  {
    set_balancing_weights(K, _leaves, _weights);
    check_petsc(weigh_jacobian(J), "the balanced rows: W J");
    _stale = false;
  }
  check_petsc(VecPointwiseMult(_load, b, _weights), "the balanced rows: VecPointwiseMult");
}

PetscErrorCode BalancedRows::weigh_jacobian(Mat J)
{
  // J may have grown beyond K's pattern (friction_jacobian).
  PetscFunctionBeginUser;
  PetscCall(MatCopy(J, _jacobian, DIFFERENT_NONZERO_PATTERN));
  PetscCall(MatDiagonalScale(_jacobian, _weights, nullptr));
  PetscFunctionReturn(0);
}

} // namespace biotcontact
