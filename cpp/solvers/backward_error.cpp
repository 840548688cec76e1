#include "solvers/backward_error.h"

#include "assembly/petsc_error.h"

#include <algorithm>
#include <cmath>
#include <vector>

namespace biotcontact
{

namespace
{
/// |A|, the entries' magnitudes in a matrix of A's layout, row by row (any
/// AIJ type, on any number of ranks).
Mat absolute_values(Mat A)
{
  Mat B;
  check_petsc(MatDuplicate(A, MAT_DO_NOT_COPY_VALUES, &B), "the backward error: MatDuplicate");
  PetscInt first = 0, end = 0;
  check_petsc(MatGetOwnershipRange(A, &first, &end), "the backward error: MatGetOwnershipRange");
  std::vector<PetscInt> at;
  std::vector<PetscScalar> magnitudes;
  for (PetscInt i = first; i < end; ++i)
  {
    PetscInt n = 0;
    const PetscInt* columns = nullptr;
    const PetscScalar* values = nullptr;
    check_petsc(MatGetRow(A, i, &n, &columns, &values), "the backward error: MatGetRow");
    at.assign(columns, columns + n);
    magnitudes.resize(n);
    std::transform(values, values + n, magnitudes.begin(), [](PetscScalar v) { return std::abs(v); });
    // Restored before B is written: one row of A may be out at a time.
    check_petsc(MatRestoreRow(A, i, &n, &columns, &values), "the backward error: MatRestoreRow");
    check_petsc(MatSetValues(B, 1, &i, static_cast<PetscInt>(at.size()), at.data(), magnitudes.data(), INSERT_VALUES),
                "the backward error: MatSetValues");
  }
  check_petsc(MatAssemblyBegin(B, MAT_FINAL_ASSEMBLY), "the backward error: MatAssemblyBegin");
  check_petsc(MatAssemblyEnd(B, MAT_FINAL_ASSEMBLY), "the backward error: MatAssemblyEnd");
  return B;
}
} // namespace

double backward_error(Mat A, Vec x, Vec b, Vec r)
{
  check_petsc(MatMult(A, x, r), "the backward error: MatMult");
  check_petsc(VecAYPX(r, -1.0, b), "the backward error: VecAYPX");
  Mat B = absolute_values(A);
  Vec magnitude, scale;
  check_petsc(VecDuplicate(x, &magnitude), "the backward error: VecDuplicate");
  check_petsc(VecDuplicate(b, &scale), "the backward error: VecDuplicate");
  check_petsc(VecCopy(x, magnitude), "the backward error: VecCopy");
  check_petsc(VecAbs(magnitude), "the backward error: VecAbs");
  check_petsc(MatMult(B, magnitude, scale), "the backward error: MatMult");
  check_petsc(VecCopy(b, magnitude), "the backward error: VecCopy"); // now |b|, in b's layout
  check_petsc(VecAbs(magnitude), "the backward error: VecAbs");
  check_petsc(VecAXPY(scale, 1.0, magnitude), "the backward error: VecAXPY");
  check_petsc(VecCopy(r, magnitude), "the backward error: VecCopy");
  check_petsc(VecAbs(magnitude), "the backward error: VecAbs");
  // VecPointwiseDivide leaves 0 where the divisor is 0.
  check_petsc(VecPointwiseDivide(magnitude, magnitude, scale), "the backward error: VecPointwiseDivide");
  PetscReal error = 0;
  check_petsc(VecNorm(magnitude, NORM_INFINITY, &error), "the backward error: VecNorm");
  check_petsc(VecDestroy(&magnitude), "the backward error: VecDestroy");
  check_petsc(VecDestroy(&scale), "the backward error: VecDestroy");
  check_petsc(MatDestroy(&B), "the backward error: MatDestroy");
  return error;
}

} // namespace biotcontact
