// What every coupling scheme (the fixed-stress split, the single solve per
// step) reports and whom it tells: the report of summary.json and
// checkpoints, and the observer that writes, prints and stops.
#pragma once

#include "time/step_control.h"
#include "time/time_grid.h"

#include <functional>
#include <stdexcept>
#include <string>

namespace biotcontact
{

/// The split did not converge within coupling.max_iterations, or a step's
/// converged state fails what it must conserve (Step::unbalanced).
struct CouplingError : std::runtime_error
{
  using std::runtime_error::runtime_error;
};

/// @brief What a run's coupling did, step by step: the counts and
/// contraction measures of summary.json (paper Theorems 1 and 2). Written
/// by the schemes, read by the summary; the schemes decide nothing from it
/// but where the run stands (windows, fine_steps).
struct CouplingReport
{
  int windows = 0;             // mechanics (coarse) steps
  long fine_steps = 0;         // flow (fine) steps: windows times q, or their sum with coupling.q = "auto"
  long coupling_iterations = 0;
  int max_iterations_per_step = 0;
  double max_contraction_ratio = 0, mean_contraction_ratio = 0;
  long ratios = 0;             // ratios held against gamma (resolved)
  long bound_violations = 0;   // resolved ratios above gamma
  long unresolved_ratios = 0;  // ratios at round-off level, logged only
  double max_coupled_residual = 0; // relative, of each converged state
  long retries = 0;            // failed steps retried with halved steps (time.retry)
  AdaptiveReport adaptive;     // time.adaptive (time/step_control.h)
  int max_window_q = 0;        // coupling.q = "auto": the largest q taken
  long q_rejections = 0;       // ... windows tried again with q = 1: the contact set changed in them
  long accelerated_windows = 0; // coupling.acceleration = "auto": windows handed to Anderson where they stagnated
  long pinned_windows = 0;      // windows accepted with pins (coupling/pins.h)
  long fallback_steps = 0;      // coupling.fallback: steps the monolithic scheme solved where the split failed
};

/// @brief The memory the schemes' controllers carry from window to window
/// (and through a checkpoint): not reported, read back to decide.
struct ControllerState
{
  // The sum of the resolved contraction ratios (their mean at the end) and
  // the scales of the stopping test: the largest p and u so far.
  double ratio_sum = 0, p_size = 0, u_size = 0;
  double fault_p_size = 0; // the largest l2 norm of the conduit faults' p_f so far
  AdaptiveState adaptive; // time.adaptive's PI controller (time/step_control.h)
  // The last window's q (1 after a single solve's step) and, with
  // coupling.q = "auto" (time/window_control.h), the largest q the next
  // may take (1 after a change of the contact set, then doubling).
  int window_q = 0, q_limit = 1;
};

/// What a coupling iteration measured: one row of iterations.csv.
struct IterationRecord
{
  int step;
  double time;
  int iteration;
  double dsigma_norm, ratio, gamma, dp_norm, du_norm;
  int active_nodes;
  // The conduit faults' p_f increment (relative, as dp_norm) and its ratio
  // to the last iteration's (NaN without conduit faults).
  double fault_dp_norm, fault_ratio;
  // The Newton steps of the iteration's contact solve (0 without contact).
  long newton_steps = 0;
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
  /// Told that a window is tried again with shorter steps (a failed solve,
  /// or an error estimate above time.adaptive.tolerance).
  std::function<void(const std::string& message)> retry;
  /// Told that the split changed its iteration in a window (Anderson's
  /// taking over where it stagnated).
  std::function<void(const std::string& message)> note;
  /// Told after each coupling iteration (window, iteration, increments dp
  /// and du): the progress of a long window.
  std::function<void(int window, int iteration, double dp, double du)> iteration;
  /// Told what each coupling iteration measured (iterations.csv).
  std::function<void(const IterationRecord&)> record;
};

/// @brief The run a scheme drives: the time grid it steps on (time.retry
/// and time.adaptive rewrite it), time.adaptive's control (null without),
/// the observer it tells, the report it fills and the controllers' state.
/// Grid, report and state are what a checkpoint keeps of it.
struct CouplingRun
{
  TimeGrid& grid;
  StepControl* control;
  const WindowObserver& observer;
  CouplingReport& report;
  ControllerState& state;
};

/// Calls f(name, field) for each field of the report and the controllers'
/// state that a checkpoint keeps: the one list that checkpoints and
/// restarts read.
template <class Report, class State, class F>
void for_each_checkpointed(Report& r, State& c, F&& f)
{
  f("windows", r.windows);
  f("coupling_iterations", r.coupling_iterations);
  f("max_iterations_per_step", r.max_iterations_per_step);
  f("max_contraction_ratio", r.max_contraction_ratio);
  f("ratios", r.ratios);
  f("bound_violations", r.bound_violations);
  f("unresolved_ratios", r.unresolved_ratios);
  f("max_coupled_residual", r.max_coupled_residual);
  f("ratio_sum", c.ratio_sum);
  f("p_size", c.p_size);
  f("u_size", c.u_size);
  f("fault_p_size", c.fault_p_size);
  f("retries", r.retries);
  f("rejected_steps", r.adaptive.rejected_steps);
  f("forced_steps", r.adaptive.forced_steps);
  f("max_error_estimate", r.adaptive.max_error_estimate);
  f("error_estimate", c.adaptive.error_estimate);
  f("p_largest", c.adaptive.p_largest);
  f("u_largest", c.adaptive.u_largest);
  f("contact_breaks", r.adaptive.contact_breaks);
  f("smooth_states", c.adaptive.smooth_states);
  f("fine_steps", r.fine_steps);
  f("window_q", c.window_q);
  f("q_limit", c.q_limit);
  f("max_window_q", r.max_window_q);
  f("q_rejections", r.q_rejections);
  f("accelerated_windows", r.accelerated_windows);
  f("fallback_steps", r.fallback_steps);
  f("pinned_windows", r.pinned_windows);
}

} // namespace biotcontact
