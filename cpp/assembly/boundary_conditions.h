// Essential boundary conditions of a scene, for the split systems and the
// monolithic one alike: prescribed displacement components, and no flow
// (w.n = 0, essential for the RT flux) where no pressure is given.
#pragma once

#include "domain/domain.h"
#include "assembly/linear_algebra.h"

#include <dolfinx/fem/Function.h>
#include <memory>
#include <vector>

namespace biotcontact
{

/// A prescribed displacement component and the function holding its values;
/// only its boundary DOFs (and their coordinates) are ever evaluated.
struct DisplacementValue
{
  const Expression* value;
  std::shared_ptr<dolfinx::fem::Function<double>> g;
  std::vector<std::int32_t> dofs; // of g's (collapsed) space, on the boundary
  std::vector<double> points;     // 3 coordinates per DOF
};

/// Dirichlet conditions for every prescribed displacement component; U is
/// the displacement space, or the displacement subspace of a mixed space.
BCs displacement_bcs(const Scene& scene, const Domain& domain,
                     std::shared_ptr<const dolfinx::fem::FunctionSpace> U,
                     std::vector<DisplacementValue>& values);

/// Evaluates the prescribed values at time t at the boundary DOFs (a closed
/// form such as Mandel's plate displacement costs a series per point).
void update(std::vector<DisplacementValue>& values, double t);

/// w.n = 0 on every boundary facet that is not a pressure boundary; Z is the
/// flux subspace of a mixed space.
std::shared_ptr<const dolfinx::fem::DirichletBC<double>>
no_flow_bc(const Scene& scene, const Domain& domain, std::shared_ptr<const dolfinx::fem::FunctionSpace> Z);

} // namespace biotcontact
