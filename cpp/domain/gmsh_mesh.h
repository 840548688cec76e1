// A gmsh mesh (.geo meshed, or .msh) read on rank 0 and distributed by
// dolfinx: its cells (a degenerate one refused), the named physical groups
// of dimension d-1 as boundaries and those of cells as regions, and the
// mesh split along the scene's faults (domain/faults.h), whose two faces
// become exterior facets. The prototype's twin is
// python_prototype/domain/gmsh_mesh.py.
#pragma once

#include "domain/domain.h"
#include "scene/scene.h"

#include <mpi.h>

namespace biotcontact
{

/// A gmsh mesh read on rank 0 and distributed by dolfinx; boundaries are its
/// named physical groups of dimension d-1. Throws SceneError, the same on
/// every rank, for what it refuses: a file gmsh cannot read, no cells or a
/// degenerate one, a fault that names no group of dimension d-1, a piece
/// nothing holds, an unknown boundary name (collective on world). The mesh
/// lives on the working ranks (domain/working_ranks.h); a rank that waits
/// gets a domain without one.
Domain read_gmsh(const Scene& scene, MPI_Comm world);

} // namespace biotcontact
