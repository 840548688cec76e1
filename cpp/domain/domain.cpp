#include "domain/domain.h"

#include <algorithm>

namespace biotcontact
{
using namespace dolfinx;

namespace
{
/// Marker 1 on `facets` (sorted and unique here).
std::shared_ptr<const mesh::MeshTags<std::int32_t>> marked(std::shared_ptr<const mesh::Mesh> mesh,
                                                           std::vector<std::int32_t> facets)
{
  std::sort(facets.begin(), facets.end());
  facets.erase(std::unique(facets.begin(), facets.end()), facets.end());
  const std::size_t n = facets.size();
  return std::make_shared<mesh::MeshTags<std::int32_t>>(mesh, mesh->topology().dim() - 1, std::move(facets),
                                                         std::vector<std::int32_t>(n, 1));
}
} // namespace

std::shared_ptr<const mesh::MeshTags<std::int32_t>> Domain::marker(const std::string& name) const
{
  return marked(mesh, boundaries.at(name));
}

std::shared_ptr<const mesh::MeshTags<std::int32_t>> Domain::fault_faces(const std::string& fault) const
{
  const Fault& f = faults.at(fault);
  std::vector<std::int32_t> facets(f.plus_facets);
  facets.insert(facets.end(), f.minus_facets.begin(), f.minus_facets.end());
  return marked(mesh, std::move(facets));
}

std::shared_ptr<const mesh::MeshTags<std::int32_t>> Domain::marker(const std::vector<std::string>& names) const
{
  std::vector<std::int32_t> facets;
  for (const std::string& name : names)
    facets.insert(facets.end(), boundaries.at(name).begin(), boundaries.at(name).end());
  return marked(mesh, std::move(facets));
}

std::vector<std::int64_t> vertex_input_indices(const dolfinx::mesh::Mesh& mesh)
{
  const int tdim = mesh.topology().dim();
  const auto c_to_v = mesh.topology().connectivity(tdim, 0);
  const auto& nodes = mesh.geometry().dofmap();
  const std::vector<std::int64_t>& input = mesh.geometry().input_global_indices();
  const auto map = mesh.topology().index_map(0);
  std::vector<std::int64_t> result(map->size_local() + map->num_ghosts());
  for (std::int32_t c = 0; c < c_to_v->num_nodes(); ++c)
  {
    auto v = c_to_v->links(c);
    auto x = nodes.links(c);
    for (std::size_t k = 0; k < v.size(); ++k)
      result[v[k]] = input[x[k]];
  }
  return result;
}

std::shared_ptr<const mesh::MeshTags<std::int32_t>> pore_pressure_faces(const Scene& scene, const Domain& domain)
{
  // Whether there are any is the same on every rank, whatever facets each holds.
  std::vector<std::int32_t> facets;
  bool any = false;
  for (const auto& [name, b] : scene.boundaries)
    if (b.pore_pressure_load)
    {
      facets.insert(facets.end(), domain.boundaries.at(name).begin(), domain.boundaries.at(name).end());
      any = true;
    }
  for (const auto& [name, f] : scene.faults)
    if (f.pore_pressure_load)
    {
      const Fault& fault = domain.faults.at(name);
      facets.insert(facets.end(), fault.plus_facets.begin(), fault.plus_facets.end());
      facets.insert(facets.end(), fault.minus_facets.begin(), fault.minus_facets.end());
      any = true;
    }
  return any ? marked(domain.mesh, std::move(facets)) : nullptr;
}

} // namespace biotcontact
