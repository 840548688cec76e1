#include "coupling/single_solve.h"

#include <algorithm>

namespace biotcontact
{

namespace
{

/// The unknowns at the start of a step, to go back to when it is retried.
struct StepStart
{
  std::vector<double> flow, displacement, monolithic;
};

std::vector<double> copy(std::span<const double> x) { return std::vector<double>(x.begin(), x.end()); }

StepStart step_start(const FlowStep* flow, const MechanicsStep* mechanics, const MonolithicStep* monolithic)
{
  return {flow ? copy(flow->unknowns()) : std::vector<double>{},
          mechanics ? copy(mechanics->u->x()->array()) : std::vector<double>{},
          monolithic ? copy(monolithic->unknowns()) : std::vector<double>{}};
}

void go_back(const StepStart& s, FlowStep* flow, MechanicsStep* mechanics, MonolithicStep* monolithic)
{
  if (flow)
    flow->set_unknowns(s.flow);
  if (mechanics)
    std::copy(s.displacement.begin(), s.displacement.end(), mechanics->u->x()->mutable_array().begin());
  if (monolithic)
    monolithic->set_unknowns(s.monolithic);
}

/// The solves of step t: the flow from the last step's pressure, then the
/// mechanics with the new one (a single physics has one of them).
void solve_step(double t, FlowStep* flow, MechanicsStep* mechanics, MonolithicStep* monolithic)
{
  if (monolithic)
    monolithic->solve(t);
  if (flow)
  {
    std::span<const double> p = flow->pressure->x()->array();
    std::copy(p.begin(), p.end(), flow->p_previous->x()->mutable_array().begin());
    flow->solve(t);
  }
  if (mechanics)
    mechanics->solve(t);
}

} // namespace

void run_single_solve(const Scene& scene, const Constants& constants, FlowStep* flow, MechanicsStep* mechanics,
                      MonolithicStep* monolithic, const WindowObserver& observer, CouplingReport& report,
                      TimeGrid& grid)
{
  int attempts = 0; // retries of the current step (time.retry)
  for (int k = report.windows + 1; k <= grid.steps(); ++k)
  {
    const double t = grid.t[k];
    if (set_time_step(constants, grid.dt[k - 1]))
    {
      if (monolithic)
        monolithic->time_step_changed();
      if (flow)
        flow->time_step_changed();
    }
    const StepStart start = step_start(flow, mechanics, monolithic);
    try
    {
      solve_step(t, flow, mechanics, monolithic);
    }
    catch (const SolverError& e)
    {
      const auto message = retry_step(scene, e.what(), k, attempts, grid, k - 1, 1, report.retries);
      if (!message)
        throw;
      observer.retry(*message);
      go_back(start, flow, mechanics, monolithic);
      --k; // the same step again, halved
      continue;
    }
    attempts = 0;
    if (flow or monolithic)
      observer.flow_state(t);
    observer.mechanics_state(t, k, 1);
    report.windows = k;
    if (observer.stop())
      break;
  }
}

} // namespace biotcontact
