// The pieces of a mesh split along faults (cells joined by shared nodes)
// and what holds each as a rigid body: a piece that the clamps, prescribed
// displacements, foundations and faults leave free to move has no unique
// displacement, and a solve would move it without bound (a block held only
// by a frictionless fault slid 4e10 m). The prototype's twin is
// python_prototype/domain/pieces.py.
#pragma once

#include "domain/faults.h"
#include "scene/scene.h"

#include <vector>

namespace biotcontact
{

/// The piece of every node of `mesh` (cells joined by their shared nodes),
/// numbered 0, 1, ... in the order of their first cell.
std::vector<std::int64_t> mesh_pieces(const InputMesh& mesh);

/// How many of a body's rigid motions (2D: 3; 3D: 6) the constraints
/// (`points`, `directions`: dim numbers each) hold: the rank of the rows
/// direction . m(point) over the rigid motions m, taken about `centre`
/// with rotations scaled by `size`.
int held_motions(const std::vector<double>& points, const std::vector<double>& directions, int dim,
                 const std::array<double, 3>& centre, double size);

/// Refuses, with SceneError "FILE: fault.NAME: ...", the first piece of the
/// split `mesh` that nothing holds: pieces held by a clamp, a prescribed
/// displacement or a foundation (frictionless: along the facet's normal;
/// with friction: every direction), then, in turn, pieces joined to held
/// ones by a fault (frictionless: along its normal; with friction, cohesion
/// or Tresca: every direction). Nothing to check in a scene without
/// mechanics.
void refuse_free_pieces(const Scene& scene, const InputMesh& mesh, const std::vector<SplitFault>& faults);

} // namespace biotcontact
