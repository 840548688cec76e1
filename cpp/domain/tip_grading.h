// The mesh graded toward the faults' tips (fault.NAME.tip_size): before gmsh
// meshes a .geo, a size field of at most tip_size + tip_grading * distance
// from each fault's tips (its edges inside the body: points in 2D, curves in
// 3D), the minimum over the faults as gmsh's background field. The square
// root of the opening at a tip is what a uniform mesh resolves worst
// (docs/theory.md, "Tips graded by the project"). The prototype's twin is
// python_prototype/domain/tip_grading.py.
#pragma once

#include "scene/scene.h"

namespace biotcontact
{

/// Sets gmsh's background size field for the faults that give tip_size (on
/// the model gmsh has open, before it meshes). Throws SceneError for a
/// fault without a tip inside the body and for a .geo that sets size
/// fields of its own (which the project's would replace).
void grade_toward_tips(const Scene& scene);

} // namespace biotcontact
