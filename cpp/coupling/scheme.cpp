#include "coupling/scheme.h"

#include "coupling/fixed_stress.h"
#include "coupling/single_solve.h"

#include <dolfinx/fem/utils.h>

namespace biotcontact
{
using namespace dolfinx;

Scheme::Scheme(const Problem& problem)
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
  compute_flux = [m](fem::Function<double>& out) { m->flux(out); };
  seismic_moments = [m] { return m->seismic_moments(); };
  fault_flow = [m](double t) { return m->fault_flow(t); };
  fault_volumes = [m] { return m->fault_volumes(); };
  take_contact_fields(*m);
  _drive = [&problem, m](CouplingRun& run) { run_single_solve(problem, *m, run); };
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
    FlowStep* f = _flow.get();
    compute_flux = [f](fem::Function<double>& out) { f->flux(out); };
    fault_flow = [f](double t) { return f->fault_flow(t); };
    fault_volumes = [f] { return f->fault_volumes(); };
    _steps.push_back(f);
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
    MechanicsStep* m = _mechanics.get();
    seismic_moments = [m] { return m->seismic_moments(); };
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
  if (scene.coupling)
  {
    const SplitSteps split{*_flow, _second_pass.get(), *_mechanics};
    _drive = [&problem, split](CouplingRun& run) { run_fixed_stress(problem, split, run); };
  }
  else
  {
    Step* one = _steps.front();
    _drive = [&problem, one](CouplingRun& run) { run_single_solve(problem, *one, run); };
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
  compute_contact = [&step] { return step.contact_state(); };
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
