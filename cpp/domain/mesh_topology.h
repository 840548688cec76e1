// The input mesh's topology before the split along faults (domain/faults.h):
// the cells of each facet and of each node, in the input numbering, on rank
// 0 before dolfinx distributes the mesh. The prototype's twin is
// python_prototype/domain/mesh_topology.py.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

namespace biotcontact
{

/// A facet by its sorted nodes (the third is -1 in 2D): the same facet seen
/// from either of its cells or from a group has one key.
using FacetKey = std::array<std::int64_t, 3>;

/// The key of the facet through the d nodes `nodes`.
FacetKey facet_key(const std::int64_t* nodes, int d);

/// @brief The input mesh's topology before the split: its cells as read
/// (every look-up uses the input numbering while the split renumbers the
/// mesh's cells), the cells of each facet and the cells of each node.
struct InputTopology
{
  int d = 2;
  std::vector<std::int64_t> cells;
  std::vector<std::pair<FacetKey, std::int64_t>> facet_cells; // sorted: a facet's cells ascending
  std::vector<std::int64_t> node_offsets, node_cells;         // each node's cells ascending
};

/// The topology of the d-simplices `cells` (d + 1 node indices each) over
/// `nodes` nodes.
InputTopology topology_of(int d, const std::vector<std::int64_t>& cells, std::size_t nodes);

/// The cells that have the facet `key` (ascending): two inside the body,
/// one on the outer boundary.
std::vector<std::int64_t> cells_of(const InputTopology& t, const FacetKey& key);

/// The position of `node` in the input cell `cell`.
int local_index(const InputTopology& t, std::int64_t cell, std::int64_t node);

} // namespace biotcontact
