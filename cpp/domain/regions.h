// Material regions: which cells each [region.NAME] of a scene holds.
#pragma once

#include "scene/scene.h"

#include <cstdint>
#include <dolfinx/mesh/Mesh.h>
#include <mpi.h>
#include <string>
#include <vector>

namespace biotcontact
{

/// @brief The region of every cell: an index into the scene's regions (in
/// the order of their names), or -1 for the top-level material.
struct CellRegions
{
  std::vector<std::string> names;    // the scene's regions, in name order
  std::vector<std::int32_t> region;  // per local cell (owned and ghost)
  std::vector<std::int64_t> counts;  // global number of cells of each region
  std::int64_t outside = 0;          // global number of cells in no region
};

/// The regions of `scene` on `mesh`. `input_region` holds, on rank 0, the
/// region of each cell of a gmsh file by its input index (the regions given
/// as physical groups; -1 elsewhere; empty for a built-in mesh); the others
/// hold the cells whose midpoint satisfies `where` (a non-zero value).
/// Throws SceneError naming the region when two regions claim one cell or
/// a region holds no cell (collective).
CellRegions locate_regions(const Scene& scene, const dolfinx::mesh::Mesh& mesh,
                           const std::vector<std::int32_t>& input_region);

/// Rank 0's part of locate_regions for a gmsh file: the region of each input
/// cell, from the cells of each named physical group of cells (`groups`,
/// input cell indices by group name). Throws SceneError naming the region
/// when its name is no group of the file or two regions claim one cell.
std::vector<std::int32_t> regions_of_groups(const Scene& scene, std::size_t num_cells,
                                            const std::map<std::string, std::vector<std::int64_t>>& groups);

} // namespace biotcontact
