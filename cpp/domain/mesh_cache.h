// The mesh cache (BIOTCONTACT_MESH_CACHE=DIR): a .geo meshed once is kept
// in DIR as a binary MSH 4.1 file named by a hash of all that gmsh's mesh
// depends on (the text of the .geo and of the files it reads, mesh.dimension,
// mesh.size_factor, mesh.refine, the faults' tip grading, gmsh's version);
// a run of the same inputs reads it instead of meshing again. A binary MSH
// file gives back the nodes, cells and groups bit for bit, so a run from
// the cache is the run that meshed. A .geo that names a file gmsh computes
// is not kept. The prototype's twin is python_prototype/domain/mesh_cache.py.
#pragma once

#include "scene/scene.h"

#include <string>

namespace biotcontact
{

/// The key of a .geo's mesh: FNV-1a (64 bits, in hex) of the inputs above;
/// geo_text is the text of the .geo and of the files it reads.
std::string mesh_cache_key(const Scene& scene, const std::string& geo_text, const std::string& gmsh_version);

/// The cache's file for the scene's mesh; "" when BIOTCONTACT_MESH_CACHE is
/// unset or empty, the mesh is no .geo or a file it reads is not known. Makes
/// the directory; throws SceneError naming the variable when it cannot.
/// gmsh is initialised (its version).
std::string mesh_cache_file(const Scene& scene);

/// Writes gmsh's mesh to `file` (binary MSH 4.1, every element) through a
/// temporary file renamed into place, so that runs sharing the cache never
/// read half a file; throws SceneError naming the variable when it cannot.
void store_mesh(const std::string& file);

} // namespace biotcontact
