#include "contact/whole_system.h"

namespace biotcontact
{

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
