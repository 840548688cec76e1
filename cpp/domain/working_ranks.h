// The ranks a run works on: a mesh too small for the ranks it was started
// on is distributed over fewer of them, since below some thousands of
// cells a rank (scene/schema.h, default_cells_per_rank) a second rank
// costs more than its share of the work saves (docs/performance.md,
// "nineteenth session"); the others wait for the exit status
// (docs/user-guide.md, "Running in parallel"). Twin:
// python_prototype/domain/working_ranks.py.
#pragma once

#include "scene/scene.h"

#include <cstdint>
#include <dolfinx/mesh/Mesh.h>
#include <mpi.h>
#include <string>

namespace biotcontact
{

/// How many of `ranks` work on a mesh of `cells` cells when each should
/// hold at least `cells_per_rank` (solver.cells_per_rank; 0: every rank
/// works): floor(cells / cells_per_rank), at least 1, at most `ranks`.
int working_ranks(std::int64_t cells, int cells_per_rank, int ranks);

/// The cells of a built-in mesh: 4 crossed triangles per rectangle, 6
/// tetrahedra per box.
std::int64_t built_in_cells(const MeshSpec& mesh);

/// The first working_ranks(cells, ...) ranks of `world` as a communicator
/// (collective on world); MPI_COMM_NULL on the ranks that wait.
MPI_Comm working_communicator(MPI_Comm world, std::int64_t cells, int cells_per_rank);

/// Completes `request`, asleep between polls (2 ms) rather than spinning
/// as a blocking MPI call does: a rank that waits for another (rank 0
/// reading a gmsh file, or the working ranks) leaves its core to it.
void wait_quietly(MPI_Request& request);

/// The log's line when fewer ranks of `world` work than were started
/// (those that hold `mesh`), empty when all do.
std::string working_ranks_line(MPI_Comm world, const dolfinx::mesh::Mesh& mesh, int cells_per_rank);

} // namespace biotcontact
