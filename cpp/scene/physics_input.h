// The readers of a scene's physics: [mechanics], [flow], [coupling] and the
// material regions [region.NAME], which replace some of their values.
#pragma once

#include "scene/schema.h"
#include "scene/section.h"

#include <string>
#include <toml++/toml.h>

namespace biotcontact
{

/// Refuses the value of `key` unless it is a positive finite number.
void positive(Section& s, const std::string& key, double value);

/// [mechanics], [flow] and, when both are there, [coupling].
void read_physics(Section& top, Scene& scene);

/// [region.NAME]: the cells of a gmsh physical group NAME, or those whose
/// midpoint satisfies `where`, with some of the scene's material values
/// replaced. Each region's physics are read by the readers of the scene's
/// own tables, so they are checked alike and errors name region.NAME.KEY.
/// Which cells a region holds is settled when the domain is made.
void read_regions(Section regions, const toml::table& root, Scene& scene);

} // namespace biotcontact
