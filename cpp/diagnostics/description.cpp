#include "diagnostics/description.h"

namespace biotcontact
{

namespace
{

void append(std::string& list, const std::string& item) { list += (list.empty() ? "" : "; ") + item; }

/// The physics and terms the scene leaves out.
std::string left_out(const Scene& scene)
{
  std::string list;
  if (!scene.flow)
    append(list, "flow (no [flow] table): no flux or pressure unknowns");
  if (!scene.mechanics)
    append(list, "mechanics (no [mechanics] table): no displacement unknowns");
  if (scene.mechanics and !scene.has_contact())
    append(list, "contact solver (no contact boundary): linear mechanics solve");
  if (scene.flow and !scene.flow->gravity)
    append(list, "gravity");
  if (scene.mechanics and !scene.mechanics->body_force and !scene.cellwise_body_force())
    append(list, "body force");
  return list;
}

/// Near-incompressible materials (P1 locks) and a gamma near 1 (the split
/// contracts slowly or not at all).
std::vector<std::string> warnings(const Problem& problem)
{
  const Scene& scene = problem.scene;
  const CellRegions& regions = problem.domain.regions;
  const Materials& materials = problem.materials;
  std::vector<std::string> found;
  for (std::size_t r = 0; scene.mechanics and r <= regions.names.size(); ++r)
  {
    const Parameters& m = r < regions.names.size() ? materials.regions[r] : materials.top;
    const double nu = m.lambda / (2 * (m.lambda + m.G));
    if (nu > 0.49 and (r < regions.names.size() or regions.outside > 0))
      found.push_back((r < regions.names.size() ? "region " + regions.names[r] + ": " : std::string()) + "nu = "
                      + std::to_string(nu) + " > 0.49: P1 displacements lock as nu -> 0.5 "
                      "(too stiff a response, worse on coarse meshes)");
  }
  if (const std::string w = gamma_warning(scene, materials.gamma_peak()); !w.empty())
    found.push_back(w);
  return found;
}

} // namespace

Description describe(const Problem& problem)
{
  const Scene& scene = problem.scene;
  const Domain& domain = problem.domain;
  Description d;
  d.left_out = left_out(scene);
  const int dim = domain.dim();
  d.lines.push_back("biotcontact: scene " + scene.name + " (" + scene.file + "), " + std::to_string(dim) + "D, "
                    + std::to_string(domain.mesh->topology().index_map(dim)->size_global()) + " cells");
  d.lines.push_back("left out: " + (d.left_out.empty() ? std::string("nothing") : d.left_out));
  const CellRegions& regions = domain.regions;
  for (std::size_t r = 0; r < regions.names.size(); ++r)
    d.lines.push_back("region " + regions.names[r] + ": " + std::to_string(regions.counts[r]) + " cells"
                      + (scene.coupling ? ", gamma = " + std::to_string(problem.materials.regions[r].gamma) : ""));
  for (const std::string& w : warnings(problem))
  {
    append(d.warnings, w);
    d.lines.push_back("warning: " + w);
  }
  return d;
}

} // namespace biotcontact
