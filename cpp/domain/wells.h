// Where the wells are: the owned cells each [well.NAME] lies in (a point
// in 2D, a vertical segment in 3D) and the share of its rate each takes,
// a well outside the mesh refused; and where a well is, in words. The
// flow's sources (assembly/wells.h) and the scene's checks
// (domain/mesh_checks.h) use them. The prototype's twin is
// python_prototype/domain/wells.py.
#pragma once

#include "domain/domain.h"
#include "scene/scene.h"

#include <cstdint>
#include <string>
#include <vector>

namespace biotcontact
{

/// @brief Where a well injects: the owned cells it lies in and the share of
/// its rate each takes (a point on a shared edge or vertex is split equally
/// among its cells; a segment by its length in each cell).
struct WellCells
{
  std::vector<std::int32_t> cells;
  std::vector<double> shares;
};

/// Where well `w` is, in words: "(x, y)", and in 3D " from z = bottom to
/// top".
std::string well_place(const WellSpec& w, int d);

/// The cells of well `w`; throws SceneError naming `key` when it is not in
/// the mesh, or its segment leaves it (collective).
WellCells locate_well(const Domain& domain, const WellSpec& w, const std::string& key);

} // namespace biotcontact
