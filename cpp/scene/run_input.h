// The readers of how a scene is run: [time] (the steps), [output] (what is
// written, when), [solver] (how each system is solved) and [reference] (the
// closed form a run is compared with).
#pragma once

#include "scene/schema.h"
#include "scene/section.h"

namespace biotcontact
{

/// [time]: the end, the first step, its growth or adaptation, the retries
/// and the scheme; fixed steps must be whole, at most Scene::max_steps and,
/// with q > 1, whole windows.
void read_time(Section& top, Scene& scene);

/// [output]: XDMF on or off, the times written, the checkpoint interval (in
/// steps) and the progress interval (seconds).
void read_output(Section output, Scene& scene);

/// [solver]: direct, iterative or auto for each system, inexact coupling,
/// and the fewest cells a rank works on (by default that of the mesh's
/// `dimension`).
void read_solver(Section solver, int dimension, SolverSpec& choices);

/// [reference]: the closed form the run is compared with ("none" switches
/// the comparison of a reference scene off, e.g. from --set).
void read_reference(Section r, Scene& scene);

} // namespace biotcontact
