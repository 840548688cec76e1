// What a run says of its scene before it starts: what the scene leaves
// out, its mesh and regions, and warnings where the method is known to
// degrade, instead of returning poor numbers silently (docs/stability.md).
#pragma once

#include "assembly/problem.h"

#include <string>
#include <vector>

namespace biotcontact
{

/// @brief The description of a run: "; "-joined lists for summary.json and
/// the lines printed at the start (warnings among them, prefixed).
struct Description
{
  std::string left_out, warnings;
  std::vector<std::string> lines;
};

Description describe(const Problem& problem);

} // namespace biotcontact
