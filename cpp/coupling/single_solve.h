// The scheme of a scene with one solve per step: the monolithic system, or
// a single physics (flow only, mechanics only).
#pragma once

#include "assembly/problem.h"
#include "coupling/coupling.h"
#include "steps/step.h"

namespace biotcontact
{

/// Runs the scene from the end of step run.report.windows (0, or a
/// restart's) to its end time, one solve of `step` per step of run.grid. A
/// step whose solve fails is retried with halved steps (time.retry);
/// otherwise the SolverError ends the run. With run.control
/// (time.adaptive) a step whose error estimate is too large is tried again,
/// shorter, and each accepted one plans the next.
void run_single_solve(const Problem& problem, Step& step, CouplingRun& run);

} // namespace biotcontact
