#include "coupling/single_solve.h"

#include "coupling/contraction.h"
#include "time/step_control.h"
#include "time/time_scheme.h"

#include <algorithm>
#include <exception>
#include <sstream>

namespace biotcontact
{

namespace
{

/// time.adaptive: whether the step's error estimate accepts step k (the
/// control then plans the next steps, otherwise the step's, shorter; a
/// step in which the active contact set changed from `active_before` is
/// accepted unestimated).
bool error_accepted(Step& step, int k, const ActiveSet& active_before, CouplingRun& run)
{
  if (!run.control)
    return true;
  const bool smooth = step.same_contact_set(active_before);
  std::string message;
  if (run.control->judge({k, step.pressure_values(), step.displacement_values(), smooth}, run.grid,
                         run.report.adaptive, run.state.adaptive, message))
    return true;
  run.observer.retry(message);
  return false;
}

/// The step's time derivative; with a new dt (time.growth, a retry,
/// time.adaptive) the step rebuilds what depends on it.
TimeDerivative begin_step(const Problem& problem, Step& step, const TimeGrid& grid, int k)
{
  const TimeDerivative d
      = time_derivative(problem.scene.time_scheme, grid.dt[k - 1], k >= 2 ? grid.dt[k - 2] : 0.0);
  if (set_time_step(problem.constants, d.effective_step(grid.dt[k - 1])))
    step.time_step_changed();
  return d;
}

/// time.retry: whether step `failed` is tried again on halved steps (the
/// grid then has them; the observer says so).
bool retried(const Problem& problem, const FailedStep& failed, int& attempts, CouplingRun& run)
{
  const auto message = retry_step(problem.scene, failed, attempts, run.report.retries, run.grid);
  if (message)
    run.observer.retry(*message);
  return message.has_value();
}

/// iterations.csv: a row per solve of step k's last advance (also of one
/// that failed), its changes relative to the largest p, u and p_f of the
/// run so far, as in the split's stopping test, and p_f's change to the
/// solve before's.
void record_solves(const Step& step, int k, double t, CouplingRun& run)
{
  const double nan = SolveRecord::none;
  ControllerState& c = run.state;
  double fault_previous = nan;
  int i = 0;
  for (const SolveRecord& s : step.solves())
  {
    c.p_size = std::max(c.p_size, s.p); // a NaN (no such field) leaves the size
    c.u_size = std::max(c.u_size, s.u);
    c.fault_p_size = std::max(c.fault_p_size, s.fault_p);
    const double fault_ratio = i > 0 and fault_previous > 0 ? s.fault_dp / fault_previous : nan;
    run.observer.record({k, t, ++i, nan, nan, nan, relative(s.dp, c.p_size), relative(s.du, c.u_size),
                         s.active_nodes, relative(s.fault_dp, c.fault_p_size), fault_ratio, s.newton_steps});
    fault_previous = s.fault_dp;
  }
}

std::string step_name(int k, double t)
{
  std::ostringstream s;
  s << "step " << k << " (t = " << t << ")";
  return s.str();
}

} // namespace

void run_single_solve(const Problem& problem, Step& step, CouplingRun& run)
{
  int attempts = 0; // retries of the current step (time.retry)
  for (int k = run.report.windows + 1; k <= run.grid.steps(); ++k)
  {
    const double t = run.grid.t[k];
    const TimeDerivative d = begin_step(problem, step, run.grid, k);
    const StepState start = step.state();
    step.begin_step();
    const ActiveSet active_before = run.control ? step.active_contact_set() : ActiveSet{};
    std::string failure; // a failed solve, or a solution that conserves too little
    std::exception_ptr error;
    try
    {
      step.advance(t, d);
      failure = step.unbalanced(t);
    }
    catch (const SolverError& e)
    {
      failure = e.what();
      error = std::current_exception();
    }
    record_solves(step, k, t, run);
    if (!failure.empty())
    {
      if (!retried(problem, {k, failure, k - 1, 1}, attempts, run))
      {
        if (error)
          std::rethrow_exception(error);
        throw CouplingError(step_name(k, t) + ": " + failure);
      }
      step.restore(start);
      --k; // the same step again, halved
      continue;
    }
    if (!error_accepted(step, k, active_before, run))
    {
      step.restore(start);
      --k; // the same step again, shorter
      continue;
    }
    attempts = 0;
    step.keep_history(start);
    step.accept(t);
    run.observer.flow_state(t);
    run.observer.mechanics_state(t, k, step.iterations());
    run.report.windows = k;
    run.report.fine_steps = k;
    run.state.window_q = 1; // a window of one fine step, for the split that takes over (BDF2's history)
    if (run.observer.stop())
      break;
  }
}

} // namespace biotcontact
