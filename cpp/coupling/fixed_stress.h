// The fixed-stress split, single-rate (q = 1) and multirate (q flow steps per
// mechanics step): alg. "Single-rate fixed-stress split" and "Multirate
// fixed-stress split" (paper section 4, eqs. 4.17-4.22), and the two-pass
// multirate variant ("multirate-two-pass"): after the
// mechanics, a second flow pass without L, with the new displacement,
// replaces the fine pressures the mechanics cannot see (docs/multirate-two-pass.md).
#pragma once

#include "diagnostics/diagnostics.h"
#include "steps/flow_step.h"
#include "steps/mechanics_step.h"
#include "output/output.h"
#include "assembly/parameters.h"
#include "steps/time_grid.h"

#include <functional>
#include <stdexcept>
#include <string>

namespace biotcontact
{

/// The split did not converge within coupling.max_iterations.
struct CouplingError : std::runtime_error
{
  using std::runtime_error::runtime_error;
};

struct CouplingReport
{
  int windows = 0;             // mechanics (coarse) steps
  long coupling_iterations = 0;
  int max_iterations_per_step = 0;
  double max_contraction_ratio = 0, mean_contraction_ratio = 0;
  long ratios = 0;             // ratios held against gamma (resolved)
  long bound_violations = 0;   // resolved ratios above gamma
  long unresolved_ratios = 0;  // ratios at round-off level, logged only
  double max_coupled_residual = 0; // relative, of each converged state
  long retries = 0;            // failed steps retried with halved steps (time.retry)
  // Carried from window to window (and through a checkpoint): the sum of
  // the resolved ratios and the scales of the stopping test.
  double ratio_sum = 0, p_size = 0, u_size = 0;
};

/// Called after each converged window: once per fine flow step (with that
/// step's solution loaded in the FlowStep), then once for the mechanics step.
struct WindowObserver
{
  std::function<void(double t)> flow_state;
  std::function<void(double t, int window, int iterations)> mechanics_state;
  /// Asked after each accepted (and written) window: true ends the run
  /// there (an interruption).
  std::function<bool()> stop;
  /// Told that a failed window is tried again with halved steps.
  std::function<void(const std::string& message)> retry;
};


/// Inexact coupling: the relative tolerance of the (iterative) linear solves
/// of a coupling iteration, one hundredth of the previous iteration's
/// relative increment max(dp, du), between iterative_tolerance (1e-10) and
/// 1e-4. Early iterations, whose increments are large, solve to a few
/// digits; the error each leaves is 1% of its increment, which the
/// contraction removes with the increment. The last iterations, with
/// increments near coupling.tolerance, solve to 1e-10 as without the rule,
/// so the converged state is the same to the tolerance.
double inexact_tolerance(double previous_increment);

/// Runs the coupled scene from t = 0 (or, when report.windows > 0, from the
/// end of that window: a restart with the state loaded) to its end time on
/// the steps of `grid` (which a retry refines),
/// filling `report` as it goes. Throws CouplingError (after logging every iteration) when a window
/// does not converge; `report` then describes the run up to that window.
/// `second_pass` is the flow step without L of "multirate-two-pass" (null
/// for the other schemes).
void run_fixed_stress(const Scene& scene, const Parameters& parameters, const Constants& constants,
                      FlowStep& flow, FlowStep* second_pass,
                      MechanicsStep& mechanics, ContractionNorm& contraction, Output& output,
                      const WindowObserver& observer, CouplingReport& report, TimeGrid& grid);

} // namespace biotcontact
