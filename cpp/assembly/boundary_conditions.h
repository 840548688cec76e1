// Essential boundary conditions of a scene, for the split systems and the
// monolithic one alike: prescribed displacement components, and the normal
// flux z.n (essential for the RT flux): prescribed on flux and rate
// boundaries, zero (no flow) wherever no pressure is given.
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

/// @brief The prescribed normal flux z.n = g of one flux or rate boundary
/// (planar): g = flux(x, t), or g = -rate(t) / measure spread uniformly.
struct FluxBoundary
{
  const Expression* flux = nullptr; // or
  const Expression* rate = nullptr;
  PlanarBoundary plane;
  std::vector<std::int32_t> cells; // the cells of its facets
  std::vector<std::int32_t> dofs;  // its DOFs in the collapsed flux space
};

/// @brief The values of the essential flux condition: zero on no-flow
/// facets, set by update() on the flux and rate boundaries.
struct FluxValues
{
  std::shared_ptr<dolfinx::fem::Function<double>> g; // on the collapsed flux space
  std::vector<FluxBoundary> boundaries;
};

/// z.n = g on every boundary facet that is not a pressure boundary (g = 0
/// but on flux and rate boundaries); Z is the flux subspace of a mixed space.
std::shared_ptr<const dolfinx::fem::DirichletBC<double>>
flux_bc(const Scene& scene, const Domain& domain, std::shared_ptr<const dolfinx::fem::FunctionSpace> Z,
        FluxValues& values);

/// Sets g on the flux and rate boundaries at time t: the RT interpolation
/// of g n on each boundary's cells, kept on its own facets only (a cell may
/// touch two boundaries).
void update(FluxValues& values, double t);

} // namespace biotcontact
