#include "output/keyed_values.h"

#include "domain/domain.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <dolfinx/fem/FunctionSpace.h>
#include <dolfinx/la/Vector.h>
#include <unordered_map>

namespace biotcontact
{
using namespace dolfinx;

namespace
{

/// @brief The input names of the entities a space's DOFs sit on, per local
/// DOF block (owned and ghost), and the orientation of each.
struct EntityNames
{
  int width = 1;
  std::vector<std::int64_t> names; // width per block, ascending
  std::vector<double> sign;        // +-1: the DOF's orientation against the names' order
};

/// The sorted input indices of a facet's vertices and the parity of the
/// permutation from the order of the partition's global vertex numbering
/// (dolfinx's orientation of the facet) to that sorted order.
double facet_name(std::span<const std::int32_t> vertices, const std::vector<std::int64_t>& input,
                  const dolfinx::common::IndexMap& vertex_map, std::int64_t* name)
{
  std::array<std::int32_t, 3> local{};
  std::array<std::int64_t, 3> global{};
  const std::size_t n = std::min<std::size_t>(vertices.size(), 3); // simplex facets
  std::copy(vertices.begin(), vertices.end(), local.begin());
  vertex_map.local_to_global(std::span(local.data(), n), std::span(global.data(), n));
  std::array<std::size_t, 3> order{0, 1, 2};
  for (std::size_t a = 1; a < n; ++a) // insertion sort of at most 3
    for (std::size_t b = a; b > 0 and global[order[b]] < global[order[b - 1]]; --b)
      std::swap(order[b], order[b - 1]);
  int inversions = 0;
  for (std::size_t a = 0; a < n; ++a)
  {
    name[a] = input[local[order[a]]];
    for (std::size_t b = a + 1; b < n; ++b)
      inversions += input[local[order[a]]] > input[local[order[b]]];
  }
  std::sort(name, name + n);
  return inversions % 2 == 0 ? 1.0 : -1.0;
}

/// The names of the DOF blocks of V: one DOF per vertex, facet or cell.
EntityNames entity_names(const dolfinx::mesh::Mesh& mesh, const dolfinx::fem::FunctionSpace& V)
{
  const int tdim = mesh.topology().dim();
  const auto& dofmap = *V.dofmap();
  const auto& layout = dofmap.element_dof_layout();
  int dim = 0;
  while (dim <= tdim and layout.num_entity_dofs(dim) == 0)
    ++dim;
  const int per_cell = dim > tdim ? 0 : mesh::cell_num_entities(mesh.topology().cell_type(), dim);
  if (dim > tdim or layout.num_entity_dofs(dim) != 1 or layout.num_dofs() != per_cell)
    throw std::runtime_error("checkpoint: a space that is not one DOF per vertex, facet or cell");
  const auto blocks = dofmap.index_map->size_local() + dofmap.index_map->num_ghosts();
  EntityNames e;
  e.width = dim == tdim - 1 ? tdim : 1;
  e.names.assign(blocks * e.width, -1);
  e.sign.assign(blocks, 1.0);
  const std::vector<std::int64_t> input = vertex_input_indices(mesh);
  const auto cells = mesh.topology().index_map(tdim);
  const auto c_to_f = dim == tdim - 1 ? mesh.topology().connectivity(tdim, dim) : nullptr;
  const auto f_to_v = dim == tdim - 1 ? mesh.topology().connectivity(dim, 0) : nullptr;
  for (std::int32_t c = 0; c < cells->size_local() + cells->num_ghosts(); ++c)
  {
    auto cell_dofs = dofmap.cell_dofs(c);
    for (int k = 0; k < per_cell; ++k)
    {
      const std::int32_t block = cell_dofs[layout.entity_dofs(dim, k)[0]];
      std::int64_t* name = e.names.data() + block * e.width;
      if (dim == 0)
        name[0] = input[mesh.topology().connectivity(tdim, 0)->links(c)[k]];
      else if (dim == tdim)
        name[0] = mesh.topology().original_cell_index[c];
      else
        e.sign[block] = facet_name(f_to_v->links(c_to_f->links(c)[k]), input, *mesh.topology().index_map(0), name);
    }
  }
  return e;
}

using Key = std::array<std::int64_t, 3>;
struct KeyHash
{
  std::size_t operator()(const Key& k) const
  {
    std::size_t h = 0;
    for (std::int64_t v : k)
      h = h * 1000003u ^ std::hash<std::int64_t>()(v);
    return h;
  }
};

Key key(const std::int64_t* name, int width)
{
  Key k{-1, -1, -1};
  std::copy(name, name + width, k.begin());
  return k;
}
} // namespace

namespace
{
/// The ghost entries of a function space's values in `unknowns` (at
/// `position`, or in its order when empty) from their owners: stored values
/// may be each rank's owned ones only (a checkpoint kept in memory, which
/// coupling.fallback hands between schemes), and a ghost left as it was
/// would enter the next assembly (collective).
void update_ghosts(const dolfinx::fem::FunctionSpace& space, std::span<const std::int32_t> position,
                   std::span<double> unknowns)
{
  const auto& dofmap = *space.dofmap();
  dolfinx::la::Vector<double> v(dofmap.index_map, dofmap.index_map_bs());
  std::span<double> a = v.mutable_array();
  auto at = [&](std::size_t entry) -> double& { return unknowns[position.empty() ? entry : position[entry]]; };
  for (std::size_t entry = 0; entry < a.size(); ++entry)
    a[entry] = at(entry);
  v.scatter_fwd();
  const std::size_t owned = static_cast<std::size_t>(dofmap.index_map->size_local() * dofmap.index_map_bs());
  for (std::size_t entry = owned; entry < a.size(); ++entry)
    at(entry) = a[entry];
}
} // namespace

KeyedValues keyed_values(const dolfinx::mesh::Mesh& mesh, const UnknownsPart& part, std::span<const double> unknowns)
{
  const auto& dofmap = *part.space->dofmap();
  const int bs = dofmap.index_map_bs();
  const EntityNames e = entity_names(mesh, *part.space);
  KeyedValues kv;
  kv.width = e.width;
  for (std::int32_t block = 0; block < dofmap.index_map->size_local(); ++block)
    for (int j = 0; j < bs; ++j)
    {
      const std::int32_t entry = block * bs + j;
      for (int w = 0; w < e.width; ++w)
        kv.keys.push_back(bs == 1 ? e.names[block * e.width + w] : e.names[block] * bs + j);
      kv.values.push_back(e.sign[block] * unknowns[part.position.empty() ? entry : part.position[entry]]);
    }
  return kv;
}

std::int64_t restore_values(const dolfinx::mesh::Mesh& mesh, const UnknownsPart& part, const KeyedValues& values,
                            std::span<double> unknowns)
{
  const auto& dofmap = *part.space->dofmap();
  const int bs = dofmap.index_map_bs();
  const EntityNames e = entity_names(mesh, *part.space);
  const std::int32_t blocks = dofmap.index_map->size_local() + dofmap.index_map->num_ghosts();
  std::unordered_map<Key, std::int32_t, KeyHash> entry_of;
  for (std::int32_t block = 0; block < blocks; ++block)
    for (int j = 0; j < bs; ++j)
    {
      const std::int64_t vertex = e.names[block] * bs + j;
      entry_of[bs == 1 ? key(&e.names[block * e.width], e.width) : key(&vertex, 1)] = block * bs + j;
    }
  std::int64_t found = 0;
  const std::int32_t owned = dofmap.index_map->size_local() * bs;
  if (values.width == e.width)
    for (std::size_t i = 0; i < values.values.size(); ++i)
      if (auto it = entry_of.find(key(&values.keys[i * values.width], values.width)); it != entry_of.end())
      {
        const std::int32_t entry = it->second;
        unknowns[part.position.empty() ? entry : part.position[entry]] = e.sign[entry / bs] * values.values[i];
        found += entry < owned;
      }
  update_ghosts(*part.space, part.position, unknowns);
  return owned - found;
}

std::vector<double> mesh_signature(const dolfinx::mesh::Mesh& mesh)
{
  const auto& geometry = mesh.geometry();
  const std::vector<std::int64_t>& input = geometry.input_global_indices();
  const auto x = geometry.x();
  double sum = 0.0;
  for (std::int32_t node = 0; node < geometry.index_map()->size_local(); ++node)
    for (int j = 0; j < geometry.dim(); ++j)
      sum += x[3 * node + j] * static_cast<double>(1 + (input[node] * 3 + j) % 1009);
  MPI_Allreduce(MPI_IN_PLACE, &sum, 1, MPI_DOUBLE, MPI_SUM, mesh.comm());
  const int tdim = mesh.topology().dim();
  return {static_cast<double>(geometry.index_map()->size_global()),
          static_cast<double>(mesh.topology().index_map(tdim)->size_global()), sum};
}

std::string mesh_difference(const std::vector<double>& stored, const std::vector<double>& current)
{
  auto size = [](const std::vector<double>& s)
  { return std::to_string(std::int64_t(s[0])) + " nodes and " + std::to_string(std::int64_t(s[1])) + " cells"; };
  if (stored.size() != 3)
    return "written for an unknown mesh";
  if (stored[0] != current[0] or stored[1] != current[1])
    return "written for " + size(stored) + ", this mesh has " + size(current);
  if (std::abs(stored[2] - current[2]) > 1e-12 * std::max(std::abs(stored[2]), std::abs(current[2])))
    return "the same numbers of nodes and cells, but the nodes moved";
  return "";
}

} // namespace biotcontact
