#include "domain/working_ranks.h"

#include <algorithm>
#include <chrono>
#include <dolfinx/common/IndexMap.h>
#include <functional>
#include <numeric>
#include <thread>

namespace biotcontact
{

int working_ranks(std::int64_t cells, int cells_per_rank, int ranks)
{
  if (cells_per_rank <= 0)
    return ranks;
  return static_cast<int>(std::clamp<std::int64_t>(cells / cells_per_rank, 1, ranks));
}

std::int64_t built_in_cells(const MeshSpec& mesh)
{
  const std::int64_t boxes = std::accumulate(mesh.cells.begin(), mesh.cells.end(), std::int64_t(1),
                                             std::multiplies<std::int64_t>());
  return boxes * (mesh.dimension == 2 ? 4 : 6);
}

MPI_Comm working_communicator(MPI_Comm world, std::int64_t cells, int cells_per_rank)
{
  int rank = 0, ranks = 1;
  MPI_Comm_rank(world, &rank);
  MPI_Comm_size(world, &ranks);
  const bool works = rank < working_ranks(cells, cells_per_rank, ranks);
  MPI_Comm comm = MPI_COMM_NULL;
  MPI_Comm_split(world, works ? 0 : MPI_UNDEFINED, rank, &comm);
  return comm;
}

void wait_quietly(MPI_Request& request)
{
  for (int done = 0; MPI_Test(&request, &done, MPI_STATUS_IGNORE), !done;)
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
}

std::string working_ranks_line(MPI_Comm world, const dolfinx::mesh::Mesh& mesh, int cells_per_rank)
{
  int ranks = 1, working = 1;
  MPI_Comm_size(world, &ranks);
  MPI_Comm_size(mesh.comm(), &working);
  if (working == ranks)
    return {};
  const std::int64_t cells = mesh.topology().index_map(mesh.topology().dim())->size_global();
  return std::to_string(working) + " of " + std::to_string(ranks) + " ranks work" + (working == 1 ? "s" : "") + ": "
         + std::to_string(cells) + " cells are fewer than solver.cells_per_rank = " + std::to_string(cells_per_rank)
         + " for each of " + std::to_string(working + 1) + " (0: every rank works)";
}

} // namespace biotcontact
