#include "coupling/single_solve.h"

#include "time/step_control.h"
#include "time/time_scheme.h"

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
    if (run.observer.stop())
      break;
  }
}

} // namespace biotcontact
