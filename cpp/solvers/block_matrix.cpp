#include "solvers/block_matrix.h"

#include "assembly/petsc_error.h"

#include <algorithm>

namespace biotcontact
{

BlockMatrix::BlockMatrix(Mat A, Mat C)
{
  int ranks = 1;
  MPI_Comm comm = MPI_COMM_NULL;
  check_petsc(PetscObjectGetComm(reinterpret_cast<PetscObject>(A), &comm), "a block matrix: PetscObjectGetComm");
  MPI_Comm_size(comm, &ranks);
  const PetscInt *a = nullptr, *c = nullptr;
  check_petsc(MatGetOwnershipRanges(A, &a), "a block matrix: MatGetOwnershipRanges");
  check_petsc(MatGetOwnershipRanges(C, &c), "a block matrix: MatGetOwnershipRanges");
  _a.assign(a, a + ranks + 1);
  _c.assign(c, c + ranks + 1);
}

PetscInt BlockMatrix::whole_index(int part, PetscInt index) const
{
  // Rank q's rows of A come after the rows of A and C of the ranks before
  // it, its rows of C after its rows of A.
  const std::vector<PetscInt>& ranges = part == 0 ? _a : _c;
  const auto q = static_cast<std::size_t>(std::upper_bound(ranges.begin(), ranges.end(), index) - ranges.begin() - 1);
  return part == 0 ? index + _c[q] : _a[q + 1] + index;
}

Mat BlockMatrix::convert(MPI_Comm comm, const std::array<Mat, 4>& blocks) const
{
  Mat nest = nullptr, whole = nullptr;
  check_petsc(MatCreateNest(comm, 2, nullptr, 2, nullptr, blocks.data(), &nest), "a block matrix: MatCreateNest");
  check_petsc(MatConvert(nest, MATAIJ, MAT_INITIAL_MATRIX, &whole), "a block matrix: MatConvert");
  check_petsc(MatDestroy(&nest), "a block matrix: MatDestroy");
  return whole;
}

void BlockMatrix::refill(Mat whole, const std::array<Mat, 4>& blocks) const
{
  std::vector<PetscInt> columns;
  for (int b = 0; b < 4; ++b)
  {
    if (!blocks[b])
      continue;
    const int row_part = b / 2, column_part = b % 2;
    PetscInt first = 0, end = 0;
    check_petsc(MatGetOwnershipRange(blocks[b], &first, &end), "a block matrix: MatGetOwnershipRange");
    for (PetscInt r = first; r < end; ++r)
    {
      PetscInt n = 0;
      const PetscInt* cols = nullptr;
      const PetscScalar* values = nullptr;
      check_petsc(MatGetRow(blocks[b], r, &n, &cols, &values), "a block matrix: MatGetRow");
      columns.resize(n);
      std::transform(cols, cols + n, columns.begin(), [&](PetscInt c) { return whole_index(column_part, c); });
      const PetscInt row = whole_index(row_part, r);
      check_petsc(MatSetValues(whole, 1, &row, n, columns.data(), values, INSERT_VALUES), "a block matrix: MatSetValues");
      check_petsc(MatRestoreRow(blocks[b], r, &n, &cols, &values), "a block matrix: MatRestoreRow");
    }
  }
  check_petsc(MatAssemblyBegin(whole, MAT_FINAL_ASSEMBLY), "a block matrix: MatAssemblyBegin");
  check_petsc(MatAssemblyEnd(whole, MAT_FINAL_ASSEMBLY), "a block matrix: MatAssemblyEnd");
}

} // namespace biotcontact
