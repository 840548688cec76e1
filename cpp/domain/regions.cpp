#include "domain/regions.h"

#include <algorithm>
#include <numeric>
#include <dolfinx/common/IndexMap.h>
#include <dolfinx/mesh/utils.h>

namespace biotcontact
{

namespace
{
std::vector<std::string> region_names(const Scene& scene)
{
  std::vector<std::string> names;
  for (const auto& [name, region] : scene.regions)
    names.push_back(name);
  return names;
}

/// The region claims a cell of another: the one-line error.
std::string overlap(const Scene& scene, const std::string& name, const std::string& other)
{
  return scene.file + ": region." + name + ": claims cells of region." + other
         + " too (a cell belongs to one region at most)";
}

/// Every rank learns rank 0's region of each input cell.
std::vector<std::int32_t> broadcast(std::vector<std::int32_t> input_region, MPI_Comm comm)
{
  std::uint64_t size = input_region.size();
  MPI_Bcast(&size, 1, MPI_UINT64_T, 0, comm);
  input_region.resize(size);
  MPI_Bcast(input_region.data(), static_cast<int>(size), MPI_INT32_T, 0, comm);
  return input_region;
}

/// The regions given by `where`, evaluated at the midpoints of the local
/// cells; the first overlap found on this rank, or an empty string.
std::string select_by_midpoint(const Scene& scene, const dolfinx::mesh::Mesh& mesh, CellRegions& r)
{
  const int tdim = mesh.topology().dim();
  std::vector<std::int32_t> cells(r.region.size());
  std::iota(cells.begin(), cells.end(), 0);
  const std::vector<double> x = dolfinx::mesh::compute_midpoints(mesh, tdim, cells);
  std::int32_t index = 0;
  for (const auto& [name, region] : scene.regions)
  {
    if (region.where)
      for (std::size_t c = 0; c < cells.size(); ++c)
      {
        if ((*region.where)(&x[3 * c], 0.0) == 0.0)
          continue;
        if (r.region[c] >= 0 and r.region[c] != index)
          return overlap(scene, name, r.names[r.region[c]]);
        r.region[c] = index;
      }
    ++index;
  }
  return "";
}
} // namespace

std::vector<std::int32_t> regions_of_groups(const Scene& scene, std::size_t num_cells,
                                            const std::map<std::string, std::vector<std::int64_t>>& groups)
{
  const std::vector<std::string> names = region_names(scene);
  std::vector<std::int32_t> region(num_cells, -1);
  for (std::int32_t index = 0; index < static_cast<std::int32_t>(names.size()); ++index)
  {
    if (scene.regions.at(names[index]).where)
      continue;
    const auto group = groups.find(names[index]);
    if (group == groups.end())
    {
      std::string known;
      for (const auto& [name, cells] : groups)
        known += (known.empty() ? "" : ", ") + name;
      throw SceneError(scene.file + ": region." + names[index] + ": no physical group of cells of that name in "
                       + scene.mesh.file + " (it has " + (known.empty() ? "none" : known)
                       + "; or select the cells with where = \"expression\")");
    }
    for (std::int64_t c : group->second)
    {
      if (region[c] >= 0 and region[c] != index)
        throw SceneError(overlap(scene, names[index], names[region[c]]));
      region[c] = index;
    }
  }
  return region;
}

CellRegions locate_regions(const Scene& scene, const dolfinx::mesh::Mesh& mesh,
                           const std::vector<std::int32_t>& input_region)
{
  CellRegions r;
  r.names = region_names(scene);
  const int tdim = mesh.topology().dim();
  const auto map = mesh.topology().index_map(tdim);
  const std::size_t owned = map->size_local();
  r.region.assign(owned + map->num_ghosts(), -1);
  MPI_Comm comm = mesh.comm();
  const bool groups = std::any_of(scene.regions.begin(), scene.regions.end(),
                                  [](const auto& entry) { return !entry.second.where; });
  if (groups)
  {
    const std::vector<std::int32_t> all = broadcast(input_region, comm);
    const std::vector<std::int64_t>& input = mesh.topology().original_cell_index;
    for (std::size_t c = 0; c < std::min(input.size(), r.region.size()); ++c)
      r.region[c] = all[input[c]];
  }
  if (!r.names.empty())
    agree_on_error(select_by_midpoint(scene, mesh, r), comm);

  std::vector<std::int64_t> local(r.names.size() + 1, 0);
  for (std::size_t c = 0; c < owned; ++c)
    ++local[r.region[c] + 1];
  std::vector<std::int64_t> global(local.size());
  MPI_Allreduce(local.data(), global.data(), static_cast<int>(local.size()), MPI_INT64_T, MPI_SUM, comm);
  r.outside = global[0];
  r.counts.assign(global.begin() + 1, global.end());
  for (std::size_t i = 0; i < r.names.size(); ++i)
    if (r.counts[i] == 0)
      throw SceneError(scene.file + ": region." + r.names[i] + ": holds no cell"
                       + (scene.regions.at(r.names[i]).where ? " (no cell midpoint satisfies where)" : ""));
  return r;
}

} // namespace biotcontact
