// The scheme of a scene with one solve per step: the monolithic system, or
// a single physics (flow only, mechanics only).
#pragma once

#include "coupling/coupling.h"
#include "coupling/step_control.h"
#include "steps/flow_step.h"
#include "steps/mechanics_step.h"
#include "steps/monolithic_step.h"
#include "steps/time_grid.h"

namespace biotcontact
{

/// Runs the scene from the end of step report.windows (0, or a restart's) to
/// its end time, one solve per step: the monolithic step, or the one step the
/// scene has (the others are null). A step whose solve fails is retried with
/// halved steps (time.retry); otherwise the SolverError ends the run. With
/// `control` (time.adaptive) a step whose error estimate is too large is
/// tried again, shorter, and each accepted one plans the next.
void run_single_solve(const Scene& scene, const Constants& constants, FlowStep* flow, MechanicsStep* mechanics,
                      MonolithicStep* monolithic, const WindowObserver& observer, CouplingReport& report,
                      TimeGrid& grid, StepControl* control);

} // namespace biotcontact
