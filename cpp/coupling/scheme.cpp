#include "coupling/scheme.h"

#include "coupling/fixed_stress.h"
#include "coupling/single_solve.h"

#include <dolfinx/fem/utils.h>

namespace biotcontact
{
using namespace dolfinx;

Scheme::Scheme(const Problem& problem) : _problem(problem)
{
  const Scene& scene = problem.scene;
  if (scene.coupling and scene.coupling->scheme == CouplingScheme::monolithic)
    make_monolithic(problem);
  else
    make_split(problem);
  if (scene.adaptive)
    step_control = std::make_unique<StepControl>(scene, p ? p->function_space() : nullptr, V);
}

/// u, z and p in one system.
void Scheme::make_monolithic(const Problem& problem)
{
  _monolithic = std::make_unique<MonolithicStep>(problem);
  MonolithicStep* m = _monolithic.get();
  _steps = {m};
  V = m->V;
  u = m->u;
  p = m->pressure;
  take_contact_fields(*m);
}

/// The flow step and the mechanics step of the split, or the one a single
/// physics has; "multirate-two-pass" adds the flow step without L.
void Scheme::make_split(const Problem& problem)
{
  const Scene& scene = problem.scene;
  if (scene.mechanics)
    V = std::make_shared<fem::FunctionSpace>(
        fem::create_functionspace(problem.forms.displacement_space, "v_0", problem.domain.mesh));
  if (scene.flow)
  {
    _flow = std::make_unique<FlowStep>(problem, scene.coupling ? V : nullptr);
    p = _flow->pressure;
    _steps.push_back(_flow.get());
  }
  if (scene.mechanics)
  {
    _mechanics = std::make_unique<MechanicsStep>(problem, V, p);
    if (_flow and _flow->fault_aperture())
    {
      _mechanics->load_fault_pressure(*_flow->fault_aperture(), _flow->fault_pressure());
      _flow->read_fault_traction(_mechanics->fault_traction());
    }
    u = _mechanics->u;
    given_pressure = _mechanics->given_pressure;
    take_contact_fields(*_mechanics);
    _steps.push_back(_mechanics.get());
  }
  if (scene.coupling and scene.coupling->scheme == CouplingScheme::multirate_two_pass)
  {
    _unstabilised = problem.materials.without_stabilisation();
    _second_pass = std::make_unique<FlowStep>(problem.with_materials(_unstabilised), V, FlowPass::second);
    if (_second_pass->fault_aperture())
      _second_pass->read_fault_traction(_mechanics->fault_traction());
    _steps.push_back(_second_pass.get());
  }
}

/// The contact fields of a step that has them.
template <class S>
void Scheme::take_contact_fields(S& step)
{
  if (!step.has_contact())
    return;
  contact_pressure = step.contact_pressure;
  contact_active = step.contact_active;
  contact_boundary = step.contact_boundary;
}

void Scheme::run(CouplingRun& run)
{
  if (_problem.scene.coupling and !_monolithic)
    run_fixed_stress(_problem, SplitSteps{*_flow, _second_pass.get(), *_mechanics}, run);
  else
    run_single_solve(_problem, *_steps.front(), run);
}

void Scheme::flux(fem::Function<double>& out) const
{
  if (_monolithic)
    _monolithic->flux(out);
  else if (_flow)
    _flow->flux(out);
}

std::vector<double> Scheme::fault_flow(double t) const
{
  if (_monolithic)
    return _monolithic->fault_flow(t);
  if (_flow)
    return _flow->fault_flow(t);
  return {};
}

SeismicMoments Scheme::seismic_moments() const
{
  if (_monolithic)
    return _monolithic->seismic_moments();
  if (_mechanics)
    return _mechanics->seismic_moments();
  return {};
}

std::vector<std::pair<std::string, FaultVolumes>> Scheme::fault_volumes() const
{
  if (_monolithic)
    return _monolithic->fault_volumes();
  if (_flow)
    return _flow->fault_volumes();
  return {};
}

std::vector<IntersectionRate> Scheme::fault_intersections() const
{
  if (_monolithic)
    return _monolithic->fault_intersections();
  if (_flow)
    return _flow->fault_intersections();
  return {};
}

ContactState Scheme::contact_state()
{
  if (_monolithic and _monolithic->has_contact())
    return _monolithic->contact_state();
  if (_mechanics and _mechanics->has_contact())
    return _mechanics->contact_state();
  return {};
}

void Scheme::start(ControllerState& state)
{
  if (step_control)
    step_control->start(p ? p->x()->array() : std::span<const double>(),
                        u ? u->x()->array() : std::span<const double>(), state.adaptive);
}

void Scheme::on_newton_step(const std::function<void(const std::string&, int)>& told)
{
  for (Step* step : _steps)
    if (step->system().has_contact())
      step->system().contact().on_newton_step([told, name = step->name()](int iteration) { told(name, iteration); });
}

History Scheme::history() const
{
  History h;
  for (const Step* step : _steps)
    for (const auto& entry : step->history())
      h.push_back(entry);
  if (step_control)
    for (const auto& entry : step_control->history())
      h.push_back(entry);
  return h;
}

double Scheme::assembly_time() const
{
  double t = 0;
  for (const Step* step : _steps)
    t += step->assembly_time;
  return t;
}

} // namespace biotcontact
