// The scene checked against its mesh before any solve: every expression
// finite where it is used, a foundation's normal outward, a flux or rate
// boundary planar, a well in the mesh (and on its fault), each refused with
// SceneError naming its key; and the normal and the measure of a planar
// boundary, which the flux and rate conditions use. The prototype's twin is
// python_prototype/domain/mesh_checks.py.
#pragma once

#include "domain/domain.h"
#include "scene/scene.h"

#include <array>
#include <mpi.h>
#include <string>

namespace biotcontact
{

/// @brief A planar boundary: its outward unit normal and its measure (a
/// length in 2D, an area in 3D), the same on every rank.
struct PlanarBoundary
{
  std::array<double, 3> normal{};
  double measure = 0;
};

/// The outward normal and the measure of the boundary `name`; throws
/// SceneError naming `key` when its facets do not lie in one plane (a flux
/// or rate boundary; collective).
PlanarBoundary planar_boundary(const Domain& domain, const std::string& name, const std::string& key);

/// Evaluates every expression of the scene where it is used (boundary
/// values at the nodes of their boundary, volume terms at the cell
/// midpoints) at the first and the last time, before any solve: a value
/// that is NaN or inf is refused with SceneError naming its key, the same
/// on every rank (collective).
void check_expressions(const Scene& scene, const Domain& domain, MPI_Comm comm);

} // namespace biotcontact
