// The fixed-stress split, single-rate (q = 1) and multirate (q flow steps per
// mechanics step): alg. "Single-rate fixed-stress split" and "Multirate
// fixed-stress split" (paper section 4, eqs. 4.17-4.22), and the two-pass
// multirate variant ("multirate-two-pass"): after the
// mechanics, a second flow pass without L, with the new displacement,
// replaces the fine pressures the mechanics cannot see (docs/multirate-two-pass.md).
#pragma once

#include "coupling/coupling.h"
#include "time/step_control.h"
#include "diagnostics/diagnostics.h"
#include "steps/flow_step.h"
#include "steps/mechanics_step.h"
#include "assembly/problem.h"
#include "time/time_grid.h"


namespace biotcontact
{

/// Inexact coupling: the relative tolerance of the (iterative) linear solves
/// of a coupling iteration, one hundredth of the previous iteration's
/// relative increment max(dp, du), between iterative_tolerance (1e-10) and
/// 1e-4. Early iterations, whose increments are large, solve to a few
/// digits; the error each leaves is 1% of its increment, which the
/// contraction removes with the increment. The last iterations, with
/// increments near coupling.tolerance, solve to 1e-10 as without the rule,
/// so the converged state is the same to the tolerance.
double inexact_tolerance(double previous_increment);

/// @brief The steps the split drives: the flow step and the mechanics step,
/// and for "multirate-two-pass" the flow step without L of its second pass
/// (null for the other schemes).
struct SplitSteps
{
  FlowStep& flow;
  FlowStep* second_pass;
  MechanicsStep& mechanics;
};

/// Runs the coupled scene from t = 0 (or, when run.report.windows > 0, from
/// the end of that window: a restart with the state loaded) to its end time
/// on the steps of run.grid (which a retry refines), filling run.report as
/// it goes and telling run.observer. Throws CouplingError (after logging
/// every iteration) when a window does not converge; the report then
/// describes the run up to that window.
void run_fixed_stress(const Problem& problem, const SplitSteps& steps, CouplingRun& run);

} // namespace biotcontact
