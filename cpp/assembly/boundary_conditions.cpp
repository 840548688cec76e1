#include "assembly/boundary_conditions.h"

#include "assembly/parameters.h"

#include <algorithm>
#include <dolfinx/fem/DirichletBC.h>
#include <dolfinx/mesh/utils.h>

namespace biotcontact
{
using namespace dolfinx;

BCs displacement_bcs(const Scene& scene, const Domain& domain, std::shared_ptr<const fem::FunctionSpace> U,
                     std::vector<DisplacementValue>& values)
{
  BCs bcs;
  const int d = domain.dim();
  for (const auto& [name, b] : scene.boundaries)
  {
    for (int i = 0; i < d; ++i)
    {
      if (!b.displacement[i])
        continue;
      auto Ui = U->sub({i});
      auto collapsed = std::make_shared<fem::FunctionSpace>(Ui->collapse().first);
      auto g = std::make_shared<fem::Function<double>>(collapsed);
      auto dofs = fem::locate_dofs_topological({*Ui, *collapsed}, d - 1, domain.boundaries.at(name));
      const std::vector<double> x = collapsed->tabulate_dof_coordinates(false);
      DisplacementValue value{&*b.displacement[i], g, dofs[1], {}};
      for (std::int32_t dof : value.dofs)
        value.points.insert(value.points.end(), x.begin() + 3 * dof, x.begin() + 3 * dof + 3);
      bcs.push_back(std::make_shared<fem::DirichletBC<double>>(g, std::move(dofs), Ui));
      values.push_back(std::move(value));
    }
  }
  return bcs;
}

void update(std::vector<DisplacementValue>& values, double t)
{
  for (auto& v : values)
  {
    std::span<double> g = v.g->x()->mutable_array();
    for (std::size_t k = 0; k < v.dofs.size(); ++k)
      g[v.dofs[k]] = (*v.value)(&v.points[3 * k], t);
  }
}

std::shared_ptr<const fem::DirichletBC<double>>
no_flow_bc(const Scene& scene, const Domain& domain, std::shared_ptr<const fem::FunctionSpace> Z)
{
  const auto& mesh = domain.mesh;
  std::vector<std::int32_t> facets = mesh::exterior_facet_indices(mesh->topology());
  for (const auto& [name, b] : scene.boundaries)
  {
    if (b.flow != BoundarySpec::Flow::pressure)
      continue;
    const std::vector<std::int32_t>& pressure = domain.boundaries.at(name);
    std::vector<std::int32_t> rest;
    std::set_difference(facets.begin(), facets.end(), pressure.begin(), pressure.end(),
                        std::back_inserter(rest));
    facets = std::move(rest);
  }
  auto collapsed = std::make_shared<fem::FunctionSpace>(Z->collapse().first);
  auto zero = std::make_shared<fem::Function<double>>(collapsed);
  auto dofs = fem::locate_dofs_topological({*Z, *collapsed}, domain.dim() - 1, facets);
  return std::make_shared<fem::DirichletBC<double>>(zero, std::move(dofs), Z);
}

} // namespace biotcontact
