// Where the conduit faults' unknowns live among the ranks: each fault cell
// (domain/fault_cells.h), numbered fault by fault in the scene's order, is
// owned by the rank that owns its first + node, so its rows sit with the
// rock they touch. Twin: python_prototype/assembly/fault_rows.py.
#pragma once

#include "domain/domain.h"
#include "scene/scene.h"

#include <cstdint>
#include <mpi.h>
#include <petscsys.h>
#include <span>
#include <vector>

namespace biotcontact
{

/// @brief The conduit faults' cells as rows of a distributed system: each
/// cell's owner and global row; rank r's cells, in the cells' order, are
/// the rows [start_r, start_r + owned_r) (contiguous, as PETSc numbers a
/// rank's rows). Vectors "of this rank's entries" hold the owned cells in
/// that order.
struct FaultRows
{
  MPI_Comm comm = MPI_COMM_NULL;
  int rank = 0;
  std::vector<int> owner;       // per cell
  std::vector<PetscInt> row;    // per cell: its global row
  std::vector<std::int64_t> mine; // this rank's cells, ascending

  std::int64_t size() const { return static_cast<std::int64_t>(owner.size()); }
  std::int32_t owned() const { return static_cast<std::int32_t>(mine.size()); }
  bool owns(std::int64_t cell) const { return owner[cell] == rank; }
  /// Every cell's values from each rank's entries (collective).
  std::vector<double> everywhere(std::span<const double> owned) const;
  /// This rank's entries of `all` (a value per cell).
  std::vector<double> entries(std::span<const double> all) const;
};

/// The rows of the scene's conduit faults in `domain` (collective).
FaultRows fault_rows(const Scene& scene, const Domain& domain);

} // namespace biotcontact
