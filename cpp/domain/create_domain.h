// Scene -> Domain: the built-in rectangle of crossed triangles or box of
// tetrahedra, with boundaries left/right (x), bottom/top (y) in 2D and
// left/right (x), front/back (y), bottom/top (z) in 3D; or a gmsh file
// (domain/gmsh_mesh.h). The prototype's twin is
// python_prototype/domain/create_domain.py.
#pragma once

#include "domain/domain.h"
#include "scene/scene.h"

#include <mpi.h>

namespace biotcontact
{

/// Builds the mesh of a scene (built-in rectangle or box, or a gmsh file)
/// on the working ranks of `world` (domain/working_ranks.h) and locates its
/// named boundaries; throws SceneError for unknown names. On a rank that
/// waits the domain has no mesh (collective on world).
Domain create_domain(const Scene& scene, MPI_Comm world);

} // namespace biotcontact
