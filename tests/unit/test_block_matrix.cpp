// Unit tests of the 2 x 2 block matrix as one AIJ matrix
// (cpp/solvers/block_matrix.h): the conversion of [[A, E], [B, C]] is the
// nest's, a refill sets every block anew, and a null block keeps its
// entries (the appended operator's A between reassemblies). The
// prototype's twin is tests/unit/test_block_matrix.py.
#include "solvers/block_matrix.h"

#include <array>
#include <gtest/gtest.h>
#include <petscmat.h>
#include <vector>

using namespace biotcontact;

namespace
{
constexpr PetscInt n_a = 4, n_c = 2, n = n_a + n_c;

/// A rows x columns AIJ matrix on one rank with entries value(i, j), zero
/// ones left out but on the diagonal of a square one.
template <typename F>
Mat aij(PetscInt rows, PetscInt columns, F value)
{
  Mat M = nullptr;
  EXPECT_EQ(MatCreateAIJ(PETSC_COMM_WORLD, PETSC_DECIDE, PETSC_DECIDE, rows, columns, columns, nullptr, 0, nullptr, &M), 0);
  for (PetscInt i = 0; i < rows; ++i)
    for (PetscInt j = 0; j < columns; ++j)
      if (const double v = value(i, j); v != 0 or (i == j and rows == columns))
        EXPECT_EQ(MatSetValue(M, i, j, v, INSERT_VALUES), 0);
  EXPECT_EQ(MatAssemblyBegin(M, MAT_FINAL_ASSEMBLY), 0);
  EXPECT_EQ(MatAssemblyEnd(M, MAT_FINAL_ASSEMBLY), 0);
  return M;
}

/// The blocks {A, E, B, C} of one structure, their entries scaled by s.
std::array<Mat, 4> blocks(double s)
{
  return {aij(n_a, n_a, [s](PetscInt i, PetscInt j) { return s * (i == j ? 4.0 : i + j == 3 ? -1.0 : 0.0); }),
          aij(n_a, n_c, [s](PetscInt i, PetscInt j) { return i == 3 - j ? s * 2.0 : 0.0; }),
          aij(n_c, n_a, [s](PetscInt i, PetscInt j) { return j == 3 - i ? s * 3.0 : 0.0; }),
          aij(n_c, n_c, [s](PetscInt i, PetscInt j) { return i == j ? s * -5.0 : 0.0; })};
}

/// Entry (i, j) of the whole matrix [[A, E], [B, C]] (one rank: A's rows,
/// then C's).
double whole_entry(const std::array<Mat, 4>& b, PetscInt i, PetscInt j)
{
  const int block = 2 * (i >= n_a) + (j >= n_a);
  double v = 0;
  EXPECT_EQ(MatGetValue(b[block], i >= n_a ? i - n_a : i, j >= n_a ? j - n_a : j, &v), 0);
  return v;
}

/// Whether `whole` holds the blocks `b`, entry by entry.
void expect_whole(Mat whole, const std::array<Mat, 4>& b)
{
  for (PetscInt i = 0; i < n; ++i)
    for (PetscInt j = 0; j < n; ++j)
    {
      double v = 0;
      EXPECT_EQ(MatGetValue(whole, i, j, &v), 0);
      EXPECT_EQ(v, whole_entry(b, i, j)) << "entry (" << i << ", " << j << ")";
    }
}

void destroy(std::array<Mat, 4>& b)
{
  for (Mat& m : b)
    EXPECT_EQ(MatDestroy(&m), 0);
}
} // namespace

TEST(BlockMatrix, RefillSetsEveryBlockAndANullBlockKeepsItsEntries)
{
  std::array<Mat, 4> first = blocks(1.0), second = blocks(2.0), third = blocks(3.0);
  const BlockMatrix layout(first[0], first[3]);
  Mat whole = layout.convert(PETSC_COMM_WORLD, first);
  expect_whole(whole, first);
  layout.refill(whole, second);
  expect_whole(whole, second);
  // A kept: its block is the second's, E, B and C the third's.
  layout.refill(whole, {nullptr, third[1], third[2], third[3]});
  expect_whole(whole, {second[0], third[1], third[2], third[3]});
  EXPECT_EQ(MatDestroy(&whole), 0);
  for (auto* b : {&first, &second, &third})
    destroy(*b);
}
