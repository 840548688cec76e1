#include "domain/mesh_topology.h"

#include <algorithm>

namespace biotcontact
{

FacetKey facet_key(const std::int64_t* nodes, int d)
{
  FacetKey key{-1, -1, -1};
  std::copy_n(nodes, d, key.begin());
  // Two or three values sorted by exchanges: std::sort over part of the
  // array makes GCC 12 warn of out-of-bounds accesses (-Warray-bounds).
  if (key[0] > key[1])
    std::swap(key[0], key[1]);
  if (d == 3 and key[1] > key[2])
    std::swap(key[1], key[2]);
  if (key[0] > key[1])
    std::swap(key[0], key[1]);
  return key;
}

InputTopology topology_of(int d, const std::vector<std::int64_t>& cells, std::size_t nodes)
{
  InputTopology t{d, cells, {}, {}, {}};
  const auto num_cells = static_cast<std::int64_t>(cells.size()) / (d + 1);
  t.node_offsets.assign(nodes + 1, 0);
  for (std::int64_t c = 0; c < num_cells; ++c)
  {
    const std::int64_t* cell = &cells[c * (d + 1)];
    for (int j = 0; j <= d; ++j)
    {
      // The facet opposite node j.
      std::array<std::int64_t, 3> facet{-1, -1, -1};
      std::copy_if(cell, cell + d + 1, facet.begin(), [&](std::int64_t v) { return v != cell[j]; });
      t.facet_cells.emplace_back(facet_key(facet.data(), d), c);
      ++t.node_offsets[cell[j] + 1];
    }
  }
  std::sort(t.facet_cells.begin(), t.facet_cells.end());
  for (std::size_t v = 1; v < t.node_offsets.size(); ++v)
    t.node_offsets[v] += t.node_offsets[v - 1];
  t.node_cells.resize(cells.size());
  std::vector<std::int64_t> next(t.node_offsets.begin(), t.node_offsets.end() - 1);
  for (std::size_t i = 0; i < cells.size(); ++i)
    t.node_cells[next[cells[i]]++] = static_cast<std::int64_t>(i) / (d + 1);
  return t;
}

/// The cells that have the facet `key` (ascending): two inside the body,
/// one on the outer boundary.
std::vector<std::int64_t> cells_of(const InputTopology& t, const FacetKey& key)
{
  const auto [first, last] = std::equal_range(t.facet_cells.begin(), t.facet_cells.end(),
                                              std::pair<FacetKey, std::int64_t>{key, 0},
                                              [](const auto& a, const auto& b) { return a.first < b.first; });
  std::vector<std::int64_t> cells;
  for (auto it = first; it != last; ++it)
    cells.push_back(it->second);
  return cells;
}

/// The position of `node` in the input cell `cell`.
int local_index(const InputTopology& t, std::int64_t cell, std::int64_t node)
{
  const std::int64_t* nodes = &t.cells[cell * (t.d + 1)];
  return static_cast<int>(std::find(nodes, nodes + t.d + 1, node) - nodes);
}

} // namespace biotcontact
