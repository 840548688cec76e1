#include "assembly/boundary_conditions.h"

#include "assembly/parameters.h"

#include <algorithm>
#include <dolfinx/fem/DirichletBC.h>
#include <dolfinx/mesh/utils.h>
#include <xtensor/xarray.hpp>
#include <xtensor/xbuilder.hpp>

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
flux_bc(const Scene& scene, const Domain& domain, std::shared_ptr<const fem::FunctionSpace> Z, FluxValues& values)
{
  const auto& mesh = domain.mesh;
  std::vector<std::int32_t> facets = mesh::exterior_facet_indices(mesh->topology());
  auto leave_out = [&facets](std::vector<std::int32_t> pressure)
  {
    std::sort(pressure.begin(), pressure.end());
    std::vector<std::int32_t> rest;
    std::set_difference(facets.begin(), facets.end(), pressure.begin(), pressure.end(),
                        std::back_inserter(rest));
    facets = std::move(rest);
  };
  for (const auto& [name, b] : scene.boundaries)
    if (b.flow == BoundarySpec::Flow::pressure)
      leave_out(domain.boundaries.at(name));
  // A fault's faces are exterior facets of the split mesh: no flow crosses
  // them ("sealing") unless they are pressure boundaries.
  for (const auto& [name, f] : scene.faults)
    if (f.flow == FaultFlow::pressure)
    {
      const Fault& fault = domain.faults.at(name);
      std::vector<std::int32_t> faces(fault.plus_facets);
      faces.insert(faces.end(), fault.minus_facets.begin(), fault.minus_facets.end());
      leave_out(std::move(faces));
    }
  auto collapsed = std::make_shared<fem::FunctionSpace>(Z->collapse().first);
  values.g = std::make_shared<fem::Function<double>>(collapsed);
  const int d = domain.dim();
  auto f_to_c = mesh->topology().connectivity(d - 1, d);
  for (const auto& [name, b] : scene.boundaries)
  {
    if (b.flow != BoundarySpec::Flow::flux)
      continue;
    FluxBoundary fb{b.rate ? nullptr : &b.flux, b.rate ? &*b.rate : nullptr,
                    planar_boundary(domain, name, "boundary." + name), {}, {}};
    for (std::int32_t f : domain.boundaries.at(name))
      fb.cells.push_back(f_to_c->links(f)[0]);
    fb.dofs = fem::locate_dofs_topological(*collapsed, d - 1, domain.boundaries.at(name));
    values.boundaries.push_back(std::move(fb));
  }
  auto dofs = fem::locate_dofs_topological({*Z, *collapsed}, d - 1, facets);
  return std::make_shared<fem::DirichletBC<double>>(values.g, std::move(dofs), Z);
}

void update(FluxValues& values, double t)
{
  if (values.boundaries.empty())
    return;
  fem::Function<double> boundary_g(values.g->function_space());
  std::span<double> g = values.g->x()->mutable_array();
  const std::size_t gdim = values.g->function_space()->mesh()->geometry().dim();
  for (const FluxBoundary& b : values.boundaries)
  {
    const double uniform = b.rate ? -(*b.rate)(0, 0, 0, t) / b.plane.measure : 0.0;
    boundary_g.interpolate(
        [&](const xt::xtensor<double, 2>& x) -> xt::xarray<double>
        {
          xt::xarray<double> v = xt::zeros<double>({gdim, x.shape(1)});
          for (std::size_t k = 0; k < x.shape(1); ++k)
          {
            const double value = b.rate ? uniform : (*b.flux)(x(0, k), x(1, k), x(2, k), t);
            for (std::size_t i = 0; i < gdim; ++i)
              v(i, k) = value * b.plane.normal[i];
          }
          return v;
        },
        b.cells);
    const std::span<const double> from = boundary_g.x()->array();
    for (std::int32_t dof : b.dofs)
      g[dof] = from[dof];
  }
}

} // namespace biotcontact
