#include "assembly/boundary_conditions.h"

#include "assembly/node_coordinates.h"
#include "assembly/parameters.h"

#include <algorithm>
#include <bit>
#include <map>
#include <dolfinx/fem/DirichletBC.h>
#include <dolfinx/fem/utils.h>
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
      const std::vector<double> x = node_coordinates(*collapsed);
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
  // them ("sealing") unless they are pressure boundaries or the flux is
  // tied across them ("transparent", fault_flux_ties).
  for (const auto& [name, f] : scene.faults)
    if (f.flow != FaultFlow::sealing)
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

std::vector<FaceRow> fault_face_rows(const Domain& domain, const dolfinx::fem::FunctionSpace& Z,
                                     const std::string& name, std::span<const double> flux)
{
  const auto& mesh = *domain.mesh;
  const int d = domain.dim();
  mesh.topology_mutable().create_connectivity(d - 1, 0);
  const Fault& fault = domain.faults.at(name);
  // Each - face's nodes (sorted) to its + face's: by facet, as a - node may
  // face two + nodes where another fault ends on this one.
  std::map<std::vector<std::int64_t>, std::vector<std::int64_t>> plus_face;
  const FaultCells& cells = fault.cells;
  for (std::size_t k = 0; k < cells.size(); ++k)
  {
    std::vector<std::int64_t> minus(cells.twins.begin() + d * k, cells.twins.begin() + d * (k + 1));
    std::sort(minus.begin(), minus.end());
    plus_face[minus] = {cells.keys.begin() + d * k, cells.keys.begin() + d * (k + 1)};
  }
  const std::vector<std::int64_t> input = vertex_input_indices(mesh);
  auto f_to_v = mesh.topology().connectivity(d - 1, 0), f_to_c = mesh.topology().connectivity(d - 1, d);
  auto c_to_f = mesh.topology().connectivity(d, d - 1);
  const auto& map = *Z.dofmap()->index_map;
  const auto& layout = Z.dofmap()->element_dof_layout();
  std::vector<FaceRow> rows;
  for (int side = 0; side < 2; ++side)
    for (std::int32_t facet : side == 0 ? fault.plus_facets : fault.minus_facets)
    {
      const std::int32_t cell = f_to_c->links(facet)[0];
      auto facets = c_to_f->links(cell);
      const int local = static_cast<int>(std::find(facets.begin(), facets.end(), facet) - facets.begin());
      const std::int32_t dof = Z.dofmap()->cell_dofs(cell)[layout.entity_dofs(d - 1, local)[0]];
      if (dof >= map.size_local())
        continue;
      FaceRow row{side, {}, map.local_range()[0] + dof, flux[dof]};
      for (std::int32_t v : f_to_v->links(facet))
        row.key.push_back(input[v]);
      std::sort(row.key.begin(), row.key.end());
      if (side == 1)
        row.key = plus_face.at(row.key);
      rows.push_back(std::move(row));
    }
  return rows;
}

FacetFlux facet_flux(const ufcx_form* L_pressure, std::shared_ptr<const fem::FunctionSpace> X, const Domain& domain,
                     const CompiledForms& forms, const Constants& constants)
{
  return [=, &domain, &forms, &constants](std::shared_ptr<const mesh::MeshTags<std::int32_t>> faces)
  {
    auto D = std::make_shared<fem::FunctionSpace>(fem::create_functionspace(forms.data_space, "source", domain.mesh));
    auto minus_one = std::make_shared<fem::Function<double>>(D);
    minus_one->x()->set(-1.0);
    const Coefficients data = {{"p_boundary", minus_one}};
    auto L = make_form(L_pressure, {X}, data, constants, faces.get());
    la::Vector<double> b(X->dofmap()->index_map, X->dofmap()->index_map_bs());
    add_vector(b, *L);
    b.scatter_rev(std::plus<double>());
    return std::vector<double>(b.array().begin(), b.array().end());
  };
}

std::vector<Tie> fault_flux_ties(const Scene& scene, const Domain& domain, const fem::FunctionSpace& Z,
                                 const FacetFlux& facet_flux)
{
  const int d = domain.dim(), width = d + 3;
  // Per row: side, key (d), DOF, the facet flux's bits.
  std::vector<std::int64_t> rows;
  for (const auto& [name, f] : scene.faults)
    if (scene.flow and f.flow == FaultFlow::transparent)
      for (const FaceRow& r : fault_face_rows(domain, Z, name, facet_flux(domain.fault_faces(name))))
      {
        rows.push_back(r.side);
        rows.insert(rows.end(), r.key.begin(), r.key.end());
        rows.push_back(r.dof);
        rows.push_back(std::bit_cast<std::int64_t>(r.flux));
      }
  const Gathered all = all_gather(rows, domain.mesh->comm());
  std::map<std::vector<std::int64_t>, std::pair<std::int64_t, double>> plus;
  for (std::size_t r = 0; r < all.values.size(); r += width)
    if (all.values[r] == 0)
      plus[{all.values.begin() + r + 1, all.values.begin() + r + 1 + d}]
          = {all.values[r + d + 1], std::bit_cast<double>(all.values[r + d + 2])};
  std::vector<Tie> ties;
  for (std::size_t r = 0; r < rows.size(); r += width)
    if (rows[r] == 1)
    {
      const auto& [i, c_plus] = plus.at({rows.begin() + r + 1, rows.begin() + r + 1 + d});
      const double c_minus = std::bit_cast<double>(rows[r + d + 2]);
      ties.push_back({static_cast<PetscInt>(i), static_cast<PetscInt>(rows[r + d + 1]), -c_plus / c_minus});
    }
  return ties;
}

} // namespace biotcontact
