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

} // namespace biotcontact
