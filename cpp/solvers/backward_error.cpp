#include "solvers/backward_error.h"

#include "assembly/petsc_error.h"

#include <algorithm>
#include <cmath>
#include <vector>

namespace biotcontact
{

void absolute_product(Mat A, Vec x, Vec y)
{
  Mat B;
  check_petsc(MatDuplicate(A, MAT_DO_NOT_COPY_VALUES, &B), "|A| |x|: MatDuplicate");
  PetscInt first = 0, end = 0;
  check_petsc(MatGetOwnershipRange(A, &first, &end), "|A| |x|: MatGetOwnershipRange");
  std::vector<PetscInt> at;
  std::vector<PetscScalar> magnitudes;
  for (PetscInt i = first; i < end; ++i)
  {
    PetscInt n = 0;
    const PetscInt* columns = nullptr;
    const PetscScalar* values = nullptr;
    check_petsc(MatGetRow(A, i, &n, &columns, &values), "|A| |x|: MatGetRow");
    at.assign(columns, columns + n);
    magnitudes.resize(n);
    std::transform(values, values + n, magnitudes.begin(), [](PetscScalar v) { return std::abs(v); });
    // Restored before B is written: one row of A may be out at a time.
    check_petsc(MatRestoreRow(A, i, &n, &columns, &values), "|A| |x|: MatRestoreRow");
    check_petsc(MatSetValues(B, 1, &i, static_cast<PetscInt>(at.size()), at.data(), magnitudes.data(), INSERT_VALUES),
                "|A| |x|: MatSetValues");
  }
  check_petsc(MatAssemblyBegin(B, MAT_FINAL_ASSEMBLY), "|A| |x|: MatAssemblyBegin");
  check_petsc(MatAssemblyEnd(B, MAT_FINAL_ASSEMBLY), "|A| |x|: MatAssemblyEnd");
  Vec magnitude;
  check_petsc(VecDuplicate(x, &magnitude), "|A| |x|: VecDuplicate");
  check_petsc(VecCopy(x, magnitude), "|A| |x|: VecCopy");
  check_petsc(VecAbs(magnitude), "|A| |x|: VecAbs");
  check_petsc(MatMult(B, magnitude, y), "|A| |x|: MatMult");
  check_petsc(VecDestroy(&magnitude), "|A| |x|: VecDestroy");
  check_petsc(MatDestroy(&B), "|A| |x|: MatDestroy");
}

double backward_error(Mat A, Vec x, Vec b, Vec r)
{
  check_petsc(MatMult(A, x, r), "the backward error: MatMult");
  check_petsc(VecAYPX(r, -1.0, b), "the backward error: VecAYPX");
  Vec magnitude, scale;
  check_petsc(VecDuplicate(b, &magnitude), "the backward error: VecDuplicate");
  check_petsc(VecDuplicate(b, &scale), "the backward error: VecDuplicate");
  absolute_product(A, x, scale);
  check_petsc(VecCopy(b, magnitude), "the backward error: VecCopy");
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
  return error;
}

} // namespace biotcontact
