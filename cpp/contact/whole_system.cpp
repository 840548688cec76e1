#include "contact/whole_system.h"

#include "solvers/linear_solver.h"

namespace biotcontact
{

namespace
{
/// Zeroes y's entries but the held `rows` where y is a worse start than
/// that, ||b - A y|| > ||b - A y_held||: a singular first Newton step of a
/// body that contact alone holds left y 1e11 off, and an iterative
/// solver's convergence test, relative to ||b||, stopped at its first
/// iteration (DIVERGED_DTOL; elastic_contact, solver.mechanics =
/// "iterative"). A and b are the clamped system's (collective).
void start_no_worse_than_held(Mat A, Vec b, Vec y, const std::vector<PetscInt>& rows)
{
  Vec held, r;
  check_petsc(VecDuplicate(y, &held), "contact solver: VecDuplicate");
  check_petsc(VecDuplicate(y, &r), "contact solver: VecDuplicate");
  PetscInt start = 0;
  check_petsc(VecGetOwnershipRange(y, &start, nullptr), "contact solver: VecGetOwnershipRange");
  const PetscScalar* values;
  PetscScalar* h;
  check_petsc(VecGetArrayRead(y, &values), "contact solver: VecGetArrayRead");
  check_petsc(VecGetArray(held, &h), "contact solver: VecGetArray");
  for (PetscInt row : rows)
    h[row - start] = values[row - start];
  check_petsc(VecRestoreArray(held, &h), "contact solver: VecRestoreArray");
  check_petsc(VecRestoreArrayRead(y, &values), "contact solver: VecRestoreArrayRead");
  auto residual = [&](Vec x)
  {
    PetscReal norm = 0;
    check_petsc(MatMult(A, x, r), "contact solver: MatMult");
    check_petsc(VecAYPX(r, -1.0, b), "contact solver: VecAYPX");
    check_petsc(VecNorm(r, NORM_2, &norm), "contact solver: VecNorm");
    return norm;
  };
  if (residual(y) > residual(held))
    check_petsc(VecCopy(held, y), "contact solver: VecCopy");
  check_petsc(VecDestroy(&r), "contact solver: VecDestroy");
  check_petsc(VecDestroy(&held), "contact solver: VecDestroy");
}
} // namespace

void solve_clamped(const WholeSystem& whole, Vec b, Vec y, const std::vector<PetscInt>& rows)
{
  // A (and the preconditioning matrix P, when it is another) with the
  // held rows and columns made identity rows.
  auto clamped_copy = [&](Mat M, Vec rhs)
  {
    Mat C;
    check_petsc(MatDuplicate(M, MAT_COPY_VALUES, &C), "contact solver: MatDuplicate");
    MatNullSpace modes = nullptr; // for AMG: the duplicate does not keep it
    check_petsc(MatGetNearNullSpace(M, &modes), "contact solver: MatGetNearNullSpace");
    if (modes)
      check_petsc(MatSetNearNullSpace(C, modes), "contact solver: MatSetNearNullSpace");
    check_petsc(MatZeroRowsColumns(C, static_cast<PetscInt>(rows.size()), rows.data(), 1.0, rhs ? y : nullptr, rhs),
                "contact solver: MatZeroRowsColumns");
    return C;
  };
  Vec rhs;
  check_petsc(VecDuplicate(b, &rhs), "contact solver: VecDuplicate");
  check_petsc(VecCopy(b, rhs), "contact solver: VecCopy");
  Mat A = clamped_copy(whole.A, rhs);
  Mat P = whole.P == whole.A ? A : clamped_copy(whole.P, nullptr);
  start_no_worse_than_held(A, rhs, y, rows);
  {
    LinearSolver clamped(whole.comm, whole.layout.prefix, A, P, whole.layout.structure, whole.layout.fields);
    clamped.solve(y, rhs);
  }
  if (P != A)
    check_petsc(MatDestroy(&P), "contact solver: MatDestroy");
  check_petsc(MatDestroy(&A), "contact solver: MatDestroy");
  check_petsc(VecDestroy(&rhs), "contact solver: VecDestroy");
}

} // namespace biotcontact
