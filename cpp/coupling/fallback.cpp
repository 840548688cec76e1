#include "coupling/fallback.h"

namespace biotcontact
{

namespace
{

/// The scene with coupling.scheme = "monolithic".
Scene monolithic(const Scene& scene)
{
  Scene m = scene;
  m.coupling->scheme = CouplingScheme::monolithic;
  m.coupling->fallback = Fallback::none;
  return m;
}

} // namespace

MonolithicFallback::MonolithicFallback(const Problem& split)
    : scene(monolithic(split.scene)), materials(make_materials(scene, split.domain, split.forms)),
      parameters(derive_parameters(scene))
{
  parameters.gamma = materials.gamma;
  constants = make_constants(scene, parameters);
  problem.emplace(Problem{scene, split.domain, split.forms, materials, parameters, constants});
  scheme = std::make_unique<Scheme>(*problem);
}

WindowObserver fallback_observer(const WindowObserver& split, SolvedStep& solved, double end,
                                 const std::function<void(double)>& write_flow)
{
  WindowObserver o = split;
  o.flow_state = [write_flow, end](double t)
  {
    if (t < end)
      write_flow(t);
  };
  o.mechanics_state = [&solved](double t, int, int iterations)
  {
    solved.t = t;
    solved.iterations += iterations;
  };
  o.stop = [&solved, end] { return solved.t >= end; }; // time.adaptive's steps may pass it
  o.retry = [retry = split.retry](const std::string& message) { retry("the monolithic scheme: " + message); };
  o.record = [&solved, record = split.record](IterationRecord r)
  {
    r.step = solved.step;
    record(r);
  };
  return o;
}

} // namespace biotcontact
