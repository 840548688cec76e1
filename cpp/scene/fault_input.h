// The readers of what a scene puts on and in its mesh: the boundaries'
// conditions [boundary.NAME] (with a contact's foundation and friction), the
// faults [fault.NAME] and the wells [well.NAME].
#pragma once

#include "scene/schema.h"
#include "scene/section.h"

namespace biotcontact
{

/// [boundary.NAME]: built-in meshes know their boundaries' names; a gmsh
/// mesh's are checked against its physical groups when the domain is made.
void read_boundaries(Section boundaries, Scene& scene);

/// [fault.NAME]: faults lie inside a gmsh mesh, on groups that are not
/// boundaries. That NAME is an interior group of the mesh, and the gap
/// >= 0 at its nodes, are checked where the mesh is split along it.
void read_faults(Section faults, Scene& scene);

/// [well.NAME]: position = [x, y], rate = expr of t; in 3D a vertical
/// segment from bottom to top (z). Whether it lies in the mesh is checked
/// when the domain is made.
void read_wells(Section wells, Scene& scene);

} // namespace biotcontact
