#include "assembly/fault_rows.h"

#include <algorithm>
#include <numeric>
#include <unordered_set>

namespace biotcontact
{

FaultRows fault_rows(const Scene& scene, const Domain& domain)
{
  FaultRows rows;
  rows.comm = domain.mesh->comm();
  int ranks = 1;
  MPI_Comm_rank(rows.comm, &rows.rank);
  MPI_Comm_size(rows.comm, &ranks);
  // The input indices of the vertices this rank owns.
  const std::vector<std::int64_t> input = vertex_input_indices(*domain.mesh);
  const std::int32_t owned_vertices = domain.mesh->topology().index_map(0)->size_local();
  const std::unordered_set<std::int64_t> owned(input.begin(), input.begin() + owned_vertices);
  const int d = domain.dim();
  for (const auto& [name, f] : scene.faults)
  {
    if (f.flow != FaultFlow::conduit)
      continue;
    const FaultCells& cells = domain.faults.at(name).cells;
    for (std::size_t k = 0; k < cells.size(); ++k)
      rows.owner.push_back(owned.count(cells.keys[d * k]) ? rows.rank : -1);
  }
  // A vertex has one owner: the largest rank claiming a cell is its only one.
  MPI_Allreduce(MPI_IN_PLACE, rows.owner.data(), static_cast<int>(rows.owner.size()), MPI_INT, MPI_MAX, rows.comm);
  std::vector<PetscInt> start(ranks + 1, 0);
  for (int& o : rows.owner)
    start[(o = std::max(o, 0)) + 1] += 1;
  std::partial_sum(start.begin(), start.end(), start.begin());
  rows.row.resize(rows.owner.size());
  for (std::size_t k = 0; k < rows.owner.size(); ++k)
  {
    rows.row[k] = start[rows.owner[k]]++;
    if (rows.owner[k] == rows.rank)
      rows.mine.push_back(static_cast<std::int64_t>(k));
  }
  return rows;
}

std::vector<double> FaultRows::everywhere(std::span<const double> owned) const
{
  int ranks = 1;
  MPI_Comm_size(comm, &ranks);
  std::vector<int> counts(ranks, 0), offsets(ranks, 0);
  for (int o : owner)
    counts[o] += 1;
  std::partial_sum(counts.begin(), counts.end() - 1, offsets.begin() + 1);
  std::vector<double> by_row(owner.size()), all(owner.size());
  MPI_Allgatherv(owned.data(), static_cast<int>(owned.size()), MPI_DOUBLE, by_row.data(), counts.data(),
                 offsets.data(), MPI_DOUBLE, comm);
  for (std::size_t k = 0; k < all.size(); ++k)
    all[k] = by_row[row[k]];
  return all;
}

std::vector<double> FaultRows::entries(std::span<const double> all) const
{
  std::vector<double> values(mine.size());
  for (std::size_t i = 0; i < mine.size(); ++i)
    values[i] = all[mine[i]];
  return values;
}

} // namespace biotcontact
