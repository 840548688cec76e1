// A 2 x 2 block matrix as one parallel AIJ matrix, as PETSc's conversion of
// a nest numbers it, and its values set again from blocks of the same
// structure without a new conversion (a system with appended unknowns,
// steps/system.h, whose blocks change at every aperture iteration). Twin:
// python_prototype/solvers/block_matrix.py.
#pragma once

#include <array>
#include <mpi.h>
#include <petscmat.h>
#include <vector>

namespace biotcontact
{

/// @brief The numbering of [[A, E], [B, C]] as one matrix: each rank's
/// rows of A, then its rows of C (A and C square, distributed by rows).
class BlockMatrix
{
public:
  /// The layout of the diagonal blocks A and C (collective).
  BlockMatrix(Mat A, Mat C);
  /// A new AIJ matrix of `blocks` {A, E, B, C} (MatConvert of their nest;
  /// collective).
  Mat convert(MPI_Comm comm, const std::array<Mat, 4>& blocks) const;
  /// Sets `whole`'s entries (from convert) to those of `blocks`, of the same
  /// structure: each rank its own rows, so nothing travels (collective). A
  /// null block keeps its entries.
  void refill(Mat whole, const std::array<Mat, 4>& blocks) const;

private:
  /// The whole matrix's index of `index` in the numbering of A (part 0) or
  /// C (part 1).
  PetscInt whole_index(int part, PetscInt index) const;
  std::vector<PetscInt> _a, _c; // per rank and one more: the ownership ranges of A and C
};

} // namespace biotcontact
