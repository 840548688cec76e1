#include "contact/friction.h"

#include <cmath>
#include <map>

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
/// Adds `weight` times row `row` of K to `sum` (column -> value).
void add_row(Mat K, PetscInt row, double weight, std::map<PetscInt, double>& sum)
{
  PetscInt n = 0;
  const PetscInt* cols = nullptr;
  const PetscScalar* vals = nullptr;
  MatGetRow(K, row, &n, &cols, &vals);
  for (PetscInt j = 0; j < n; ++j)
    sum[cols[j]] += weight * vals[j];
  MatRestoreRow(K, row, &n, &cols, &vals);
}

/// The generalised Jacobian's row r of constraint f, as column -> value;
/// `first` is the global index of this rank's first row.
std::map<PetscInt, double> jacobian_row(const FrictionalConstraint& f, const FrictionTerm& t, int r,
                                        const FrictionPoint& at, Mat K, PetscInt first)
{
  std::map<PetscInt, double> row;
  const DiscProjection& p = t.projection;
  for (int q = 0; q < at.tangents; ++q)
  {
    const PetscInt i = f.tangential[q];
    const double d = p.d_trial[2 * r + q];
    add_row(K, first + i, (r == q ? 1.0 : 0.0) - d, row);
    row[first + i] += d * t.stiffness;
  }
  if (const double w = -t.slope * f.sign * p.d_bound[r]; w != 0)
    add_row(K, first + f.normal, w, row);
  return row;
}
} // namespace

void friction_jacobian(const std::vector<FrictionalConstraint>& constraints, const FrictionPoint& at, Mat K,
                       Mat J)
{
  MatCopy(K, J, SUBSET_NONZERO_PATTERN);
  PetscInt first = 0;
  MatGetOwnershipRange(K, &first, nullptr);
  std::vector<PetscInt> cols;
  std::vector<PetscScalar> vals;
  for (const FrictionalConstraint& f : constraints)
  {
    const FrictionTerm t = friction_term(f, at);
    for (int r = 0; r < at.tangents; ++r)
    {
      const std::map<PetscInt, double> row = jacobian_row(f, t, r, at, K, first);
      cols.clear(), vals.clear();
      for (const auto& [c, v] : row)
        cols.push_back(c), vals.push_back(v);
      const PetscInt i = first + f.tangential[r];
      MatSetValues(J, 1, &i, static_cast<PetscInt>(cols.size()), cols.data(), vals.data(), INSERT_VALUES);
    }
  }
  MatAssemblyBegin(J, MAT_FINAL_ASSEMBLY);
  MatAssemblyEnd(J, MAT_FINAL_ASSEMBLY);
}

} // namespace biotcontact
