#include "coupling/single_solve.h"

#include "steps/time_scheme.h"

#include <algorithm>

namespace biotcontact
{

namespace
{

/// The unknowns at the start of a step, to go back to when it is retried,
/// and the accumulation's state (pressure, and displacement of the
/// monolithic step), BDF2's memory once the step is accepted.
struct StepStart
{
  std::vector<double> flow, displacement, monolithic, p, u;
};

std::vector<double> copy(std::span<const double> x) { return std::vector<double>(x.begin(), x.end()); }

void assign(dolfinx::fem::Function<double>& f, const std::vector<double>& values)
{
  std::copy(values.begin(), values.end(), f.x()->mutable_array().begin());
}

StepStart step_start(const FlowStep* flow, const MechanicsStep* mechanics, const MonolithicStep* monolithic)
{
  StepStart s;
  if (flow)
    s.flow = copy(flow->unknowns());
  if (mechanics)
    s.displacement = copy(mechanics->u->x()->array());
  if (monolithic)
    s.monolithic = copy(monolithic->unknowns());
  if (flow)
    s.p = copy(flow->pressure->x()->array());
  if (monolithic)
  {
    s.p = copy(monolithic->pressure->x()->array());
    s.u = copy(monolithic->u->x()->array());
  }
  return s;
}

/// An accepted step's start becomes the state one step before the next.
void keep_history(const StepStart& s, FlowStep* flow, MonolithicStep* monolithic)
{
  if (flow)
    assign(*flow->p_before, s.p);
  if (monolithic)
  {
    assign(*monolithic->p_before, s.p);
    assign(*monolithic->u_before, s.u);
  }
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

/// The solves of step t: the flow from the last step's pressure (BDF2: its
/// history value, time_scheme.h), then the mechanics with the new one (a
/// single physics has one of them).
void solve_step(double t, const TimeDerivative& d, FlowStep* flow, MechanicsStep* mechanics,
                MonolithicStep* monolithic)
{
  if (monolithic)
    monolithic->solve(t, d);
  if (flow)
  {
    assign(*flow->p_previous, history_value(d, flow->pressure->x()->array(), flow->p_before->x()->array()));
    flow->solve(t);
  }
  if (mechanics)
    mechanics->solve(t);
}

/// The contact active set of the step's displacement (empty without contact).
ActiveSet active_contact_set(MechanicsStep* mechanics, MonolithicStep* monolithic)
{
  return mechanics ? mechanics->active_contact_set() : monolithic ? monolithic->active_contact_set() : ActiveSet{};
}

/// Whether the step's displacement has the contact active set `before`
/// (collective; true without mechanics).
bool same_contact_set(MechanicsStep* mechanics, MonolithicStep* monolithic, const ActiveSet& before)
{
  if (!mechanics and !monolithic)
    return true;
  const auto& u = mechanics ? *mechanics->u : *monolithic->u;
  return same_active_set(active_contact_set(mechanics, monolithic), before, u.function_space()->mesh()->comm());
}

/// time.adaptive: whether the step's error estimate accepts it (the control
/// then plans the next steps, otherwise the step's, shorter; a step in which
/// the active contact set changed from `active_before` is accepted
/// unestimated).
bool error_accepted(StepControl* control, TimeGrid& grid, int k, const FlowStep* flow, MechanicsStep* mechanics,
                    MonolithicStep* monolithic, const ActiveSet& active_before, CouplingReport& report,
                    const WindowObserver& observer)
{
  if (!control)
    return true;
  const bool smooth = same_contact_set(mechanics, monolithic, active_before);
  std::span<const double> p, u;
  if (flow or monolithic)
    p = (flow ? flow->pressure : monolithic->pressure)->x()->array();
  if (mechanics or monolithic)
    u = (mechanics ? mechanics->u : monolithic->u)->x()->array();
  std::string message;
  if (control->judge(grid, k, p, u, smooth, report, message))
    return true;
  observer.retry(message);
  return false;
}

} // namespace

void run_single_solve(const Scene& scene, const Constants& constants, FlowStep* flow, MechanicsStep* mechanics,
                      MonolithicStep* monolithic, const WindowObserver& observer, CouplingReport& report,
                      TimeGrid& grid, StepControl* control)
{
  int attempts = 0; // retries of the current step (time.retry)
  for (int k = report.windows + 1; k <= grid.steps(); ++k)
  {
    const double t = grid.t[k];
    const TimeDerivative d = time_derivative(scene.time_scheme, grid.dt[k - 1], k >= 2 ? grid.dt[k - 2] : 0.0);
    if (set_time_step(constants, d.effective_step(grid.dt[k - 1])))
    {
      if (monolithic)
        monolithic->time_step_changed();
      if (flow)
        flow->time_step_changed();
    }
    const StepStart start = step_start(flow, mechanics, monolithic);
    const ActiveSet active_before = control ? active_contact_set(mechanics, monolithic) : ActiveSet{};
    try
    {
      solve_step(t, d, flow, mechanics, monolithic);
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
    if (!error_accepted(control, grid, k, flow, mechanics, monolithic, active_before, report, observer))
    {
      go_back(start, flow, mechanics, monolithic);
      --k; // the same step again, shorter
      continue;
    }
    attempts = 0;
    keep_history(start, flow, monolithic);
    if (flow or monolithic)
      observer.flow_state(t);
    observer.mechanics_state(t, k, 1);
    report.windows = k;
    report.fine_steps = k;
    if (observer.stop())
      break;
  }
}

} // namespace biotcontact
