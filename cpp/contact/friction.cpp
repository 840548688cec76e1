#include "contact/friction.h"

#include <cmath>
#include <map>
#include <type_traits>

namespace biotcontact
{

FrictionTerm friction_term(const FrictionalConstraint& f, const FrictionPoint& at)
{
  FrictionTerm t;
  const double s = at.scale;
  t.normal = -f.sign * at.R[f.normal] * s / f.lumped;
  // Closed as the VI decides its active set: on the bound and pressed. A
  // pair on the bound that its force pulls off is released by the VI's
  // step; held by the bound of a cohesion or Tresca meanwhile, it would
  // stick while it opens, and the two decisions would cycle.
  t.closed = on_foundation(f.gap - f.sign * at.X[f.normal] * s, s) and t.normal > 0;
  if (t.closed)
  {
    t.bound = slip_bound(f.law, t.normal) * f.lumped;
    t.slope = slip_bound_slope(f.law, t.normal);
  }
  // One c for the constraint, the mean of K's diagonal on its tangential
  // unknowns: with a c per unknown the slip c^-1 (theta - t_T) would not
  // point along t_T (friction would not be isotropic).
  for (int r = 0; r < at.tangents; ++r)
    t.stiffness += at.stiffness[f.tangential[r]] / at.tangents;
  std::array<double, 2> trial{0, 0};
  for (int r = 0; r < at.tangents; ++r)
  {
    const PetscInt i = f.tangential[r];
    t.increment[r] = at.X[i] * s - at.start[i];
    trial[r] = -at.R[i] * s + t.stiffness * t.increment[r];
  }
  t.projection = project_on_disc(t.bound, trial, at.tangents);
  return t;
}

void add_friction_forces(const std::vector<FrictionalConstraint>& constraints, const FrictionPoint& at,
                         PetscScalar* F)
{
  for (const FrictionalConstraint& f : constraints)
  {
    const FrictionTerm t = friction_term(f, at);
    for (int r = 0; r < at.tangents; ++r)
      F[f.tangential[r]] += t.projection.force[r] / at.scale;
  }
}

namespace
{
/// The weights of the generalised Jacobian's row r of constraint f: of
/// K's rows T_q (1 - D_rq), of its row N, and D_rq c on the diagonal.
struct RowWeights
{
  std::array<double, 2> tangential{0, 0}, diagonal{0, 0};
  double normal = 0;
};

RowWeights row_weights(const FrictionalConstraint& f, const FrictionTerm& t, int r, int tangents)
{
  RowWeights w;
  for (int q = 0; q < tangents; ++q)
  {
    const double d = t.projection.d_trial[2 * r + q];
    w.tangential[q] = (r == q ? 1.0 : 0.0) - d;
    w.diagonal[q] = d * t.stiffness;
  }
  w.normal = -t.slope * f.sign * t.projection.d_bound[r];
  return w;
}

/// Adds `weight` times row `row` of K to `sum` (column -> value).
PetscErrorCode add_row(Mat K, PetscInt row, double weight, std::map<PetscInt, double>& sum)
{
  PetscInt n = 0;
  const PetscInt* cols = nullptr;
  const PetscScalar* vals = nullptr;
  PetscFunctionBeginUser;
  PetscCall(MatGetRow(K, row, &n, &cols, &vals));
  for (PetscInt j = 0; j < n; ++j)
    sum[cols[j]] += weight * vals[j];
  PetscCall(MatRestoreRow(K, row, &n, &cols, &vals));
  PetscFunctionReturn(0);
}

/// The rows of K this rank owns, from global row `first`.
struct OwnedRows
{
  Mat K;
  PetscInt first;
};

/// The generalised Jacobian's row r of constraint f, as column -> value.
PetscErrorCode jacobian_row(const FrictionalConstraint& f, const FrictionTerm& t, int r, const FrictionPoint& at,
                            OwnedRows K, std::map<PetscInt, double>& row)
{
  PetscFunctionBeginUser;
  row.clear();
  const RowWeights w = row_weights(f, t, r, at.tangents);
  for (int q = 0; q < at.tangents; ++q)
  {
    PetscCall(add_row(K.K, K.first + f.tangential[q], w.tangential[q], row));
    row[K.first + f.tangential[q]] += w.diagonal[q];
  }
  if (w.normal != 0)
    PetscCall(add_row(K.K, K.first + f.normal, w.normal, row));
  PetscFunctionReturn(0);
}

/// friction_jacobian on a dense K (the condensed path's H): the rows
/// combined column by column, in place in J's array.
PetscErrorCode dense_jacobian(const std::vector<FrictionalConstraint>& constraints, const FrictionPoint& at, Mat K,
                              Mat J)
{
  const PetscScalar* k = nullptr;
  PetscScalar* j = nullptr;
  PetscInt m = 0, lk = 0, lj = 0;
  PetscFunctionBeginUser;
  PetscCall(MatGetSize(K, &m, nullptr));
  PetscCall(MatDenseGetLDA(K, &lk));
  PetscCall(MatDenseGetLDA(J, &lj));
  PetscCall(MatDenseGetArrayRead(K, &k));
  PetscCall(MatDenseGetArray(J, &j));
  for (const FrictionalConstraint& f : constraints)
  {
    const FrictionTerm t = friction_term(f, at);
    for (int r = 0; r < at.tangents; ++r)
    {
      const RowWeights w = row_weights(f, t, r, at.tangents);
      const PetscInt i = f.tangential[r];
      for (PetscInt col = 0; col < m; ++col) // column-major: (row, col) at row + col lda
      {
        double v = w.normal * k[f.normal + col * lk];
        for (int q = 0; q < at.tangents; ++q)
          v += w.tangential[q] * k[f.tangential[q] + col * lk];
        j[i + col * lj] = v;
      }
      for (int q = 0; q < at.tangents; ++q)
        j[i + f.tangential[q] * lj] += w.diagonal[q];
    }
  }
  PetscCall(MatDenseRestoreArrayRead(K, &k));
  PetscCall(MatDenseRestoreArray(J, &j));
  PetscFunctionReturn(0);
}
} // namespace

PetscErrorCode friction_jacobian(const std::vector<FrictionalConstraint>& constraints, const FrictionPoint& at,
                                 Mat K, Mat J)
{
  PetscFunctionBeginUser;
  PetscCall(MatCopy(K, J, SUBSET_NONZERO_PATTERN));
  PetscBool dense = PETSC_FALSE;
  PetscCall(PetscObjectTypeCompare(reinterpret_cast<PetscObject>(K), MATSEQDENSE, &dense));
  if (dense)
  {
    PetscCall(dense_jacobian(constraints, at, K, J));
    PetscFunctionReturn(0);
  }
  OwnedRows rows{K, 0};
  PetscCall(MatGetOwnershipRange(K, &rows.first, nullptr));
  std::map<PetscInt, double> row;
  std::vector<PetscInt> cols;
  std::vector<PetscScalar> vals;
  for (const FrictionalConstraint& f : constraints)
  {
    const FrictionTerm t = friction_term(f, at);
    for (int r = 0; r < at.tangents; ++r)
    {
      PetscCall(jacobian_row(f, t, r, at, rows, row));
      cols.clear(), vals.clear();
      for (const auto& [c, v] : row)
        cols.push_back(c), vals.push_back(v);
      const PetscInt i = rows.first + f.tangential[r];
      PetscCall(MatSetValues(J, 1, &i, static_cast<PetscInt>(cols.size()), cols.data(), vals.data(), INSERT_VALUES));
    }
  }
  PetscCall(MatAssemblyBegin(J, MAT_FINAL_ASSEMBLY));
  PetscCall(MatAssemblyEnd(J, MAT_FINAL_ASSEMBLY));
  PetscFunctionReturn(0);
}

std::vector<double> jacobian_weights(const std::vector<FrictionalConstraint>& constraints, const FrictionPoint& at)
{
  std::vector<double> weights;
  for (const FrictionalConstraint& f : constraints)
  {
    const FrictionTerm t = friction_term(f, at);
    for (int r = 0; r < at.tangents; ++r)
    {
      const RowWeights w = row_weights(f, t, r, at.tangents);
      weights.insert(weights.end(), {w.tangential[0], w.tangential[1], w.diagonal[0], w.diagonal[1], w.normal});
    }
  }
  return weights;
}

std::vector<FrictionalConstraint> all_gather_constraints(const std::vector<FrictionalConstraint>& mine, MPI_Comm comm)
{
  static_assert(std::is_trivially_copyable_v<FrictionalConstraint>);
  int ranks = 1;
  MPI_Comm_size(comm, &ranks);
  const int bytes = static_cast<int>(mine.size() * sizeof(FrictionalConstraint));
  std::vector<int> counts(ranks), starts(ranks + 1, 0);
  MPI_Allgather(&bytes, 1, MPI_INT, counts.data(), 1, MPI_INT, comm);
  for (int r = 0; r < ranks; ++r)
    starts[r + 1] = starts[r] + counts[r];
  std::vector<FrictionalConstraint> all(starts[ranks] / sizeof(FrictionalConstraint));
  MPI_Allgatherv(mine.data(), bytes, MPI_BYTE, all.data(), counts.data(), starts.data(), MPI_BYTE, comm);
  return all;
}

} // namespace biotcontact
