#include "contact/contact_set.h"

#include "assembly/linear_algebra.h"
#include "assembly/petsc_error.h"

#include <algorithm>
#include <cmath>
#include <dolfinx/fem/DirichletBC.h>
#include <dolfinx/fem/FunctionSpace.h>

namespace biotcontact
{
using namespace dolfinx;

std::shared_ptr<fem::Function<double>> contact_boundary_flag(const ContactSet& set)
{
  auto flag = std::make_shared<fem::Function<double>>(set.output_space);
  std::span<double> values = flag->x()->mutable_array();
  for (std::int32_t dof : set.output_dofs)
    values[dof] = 1.0;
  flag->x()->scatter_fwd();
  flag->name = "contact_boundary";
  return flag;
}

void make_contact_fields(const ContactSet& set, std::shared_ptr<fem::Function<double>>& pressure,
                         std::shared_ptr<fem::Function<double>>& active, std::shared_ptr<fem::Function<double>>& boundary)
{
  pressure = std::make_shared<fem::Function<double>>(set.output_space);
  active = std::make_shared<fem::Function<double>>(set.output_space);
  boundary = contact_boundary_flag(set);
}

/// Flags of the DOFs of V (unrolled, local) whose value a displacement
/// condition prescribes.
std::vector<char> prescribed_dofs(const Scene& scene, const Domain& domain, const fem::FunctionSpace& V)
{
  const auto& map = *V.dofmap()->index_map;
  const int bs = V.dofmap()->index_map_bs();
  std::vector<char> prescribed(bs * (map.size_local() + map.num_ghosts()), 0);
  for (const auto& [name, b] : scene.boundaries)
    for (int i = 0; i < domain.dim(); ++i)
      if (b.displacement[i])
        for (std::int32_t dof : fem::locate_dofs_topological(*V.sub({i}), domain.dim() - 1, domain.boundaries.at(name)))
          prescribed[dof] = 1;
  return prescribed;
}

/// The lumped boundary measure of each DOF of V on `facets`: the integral
/// of its hat function over them.
la::Vector<double> lumped_measure(const Domain& domain, const CompiledForms& forms,
                                  std::shared_ptr<const fem::FunctionSpace> V, std::vector<std::int32_t> facets)
{
  auto marker = std::make_shared<mesh::MeshTags<std::int32_t>>(domain.mesh, domain.dim() - 1, facets,
                                                               std::vector<std::int32_t>(facets.size(), 1));
  la::Vector<double> lumped(V->dofmap()->index_map, V->dofmap()->index_map_bs());
  const Constants ones = {
      {"ones", std::make_shared<const fem::Constant<double>>(std::vector<double>(domain.dim(), 1.0))}};
  add_vector(lumped, *make_form(forms.L_lumped_boundary, {V}, {}, ones, marker.get()));
  lumped.scatter_rev(std::plus<double>());
  return lumped;
}

ContactLaw constraint_law(const ContactSet& set, std::size_t k)
{
  ContactLaw law = set.laws[set.boundary[k]];
  if (!set.bonded.empty() and !set.bonded[k])
    law.cohesion = 0;
  return law;
}

bool any_frictional(const ContactSet& set, MPI_Comm comm)
{
  int local = std::any_of(set.frictional.begin(), set.frictional.end(), [](char f) { return f != 0; }), any = 0;
  MPI_Allreduce(&local, &any, 1, MPI_INT, MPI_MAX, comm);
  return any;
}

double displacement_scale(const ContactSet& set, std::span<const std::int32_t> displacement_dofs, Vec x,
                          MPI_Comm comm)
{
  double local = 0;
  for (double g : set.gap)
    local = std::max(local, g);
  const PetscScalar* X;
  check_petsc(VecGetArrayRead(x, &X), "contact solver: VecGetArrayRead of x");
  for (std::int32_t dof : displacement_dofs)
    local = std::max(local, std::abs(X[dof]));
  check_petsc(VecRestoreArrayRead(x, &X), "contact solver: VecRestoreArrayRead of x");
  double global = 0;
  MPI_Allreduce(&local, &global, 1, MPI_DOUBLE, MPI_MAX, comm);
  return global > 0 ? global : 1.0;
}

std::vector<double> pair_shear_moduli(const ContactSet& set, const fem::FunctionSpace& V,
                                      const fem::Function<double>& G)
{
  // Per node, the sum of G and the count of its cells, each cell counted
  // on the rank that owns it and summed onto the node's owner: the same
  // mean on any partition (a node on a layer interface has cells of both).
  const fem::DofMap& nodes = *V.dofmap();
  const fem::DofMap& cells_G = *G.function_space()->dofmap();
  const auto cell_map = V.mesh()->topology().index_map(V.mesh()->topology().dim());
  la::Vector<double> sum(nodes.index_map, 1), count(nodes.index_map, 1);
  std::span<double> s = sum.mutable_array(), n = count.mutable_array();
  std::span<const double> g = G.x()->array();
  for (std::int32_t c = 0; c < cell_map->size_local(); ++c)
    for (std::int32_t node : nodes.cell_dofs(c))
      s[node] += g[cells_G.cell_dofs(c)[0]], n[node] += 1;
  sum.scatter_rev(std::plus<double>());
  count.scatter_rev(std::plus<double>());
  const int bs = nodes.bs();
  std::vector<double> moduli(set.dofs.size(), 0.0);
  for (std::size_t k = 0; k < set.dofs.size(); ++k)
    if (set.pair_node[k] >= 0) // its + node, owned here
      moduli[k] = s[set.dofs[k] / bs] / n[set.dofs[k] / bs];
  return moduli;
}

} // namespace biotcontact
