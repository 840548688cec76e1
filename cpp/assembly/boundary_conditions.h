// Essential boundary conditions of a scene, for the split systems and the
// monolithic one alike: prescribed displacement components, and the normal
// flux z.n (essential for the RT flux): prescribed on flux and rate
// boundaries, zero (no flow) wherever no pressure is given.
#pragma once

#include "domain/domain.h"
#include "domain/mesh_checks.h"
#include "assembly/forms.h"
#include "assembly/linear_algebra.h"
#include "assembly/tied_dofs.h"

#include <dolfinx/fem/Function.h>
#include <functional>
#include <memory>
#include <span>
#include <string>
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

/// The flux of each basis function of a mixed space with an RT0 part out
/// through the given facets, <w.n, 1> (a vector like the space's, owned
/// entries complete): the step's boundary-pressure load with p_D = -1.
using FacetFlux = std::function<std::vector<double>(std::shared_ptr<const dolfinx::mesh::MeshTags<std::int32_t>>)>;

/// The FacetFlux of the mixed space X from its boundary-pressure load
/// `L_pressure` (forms/biot.py: -<p_D, w.n> on the marked facets).
FacetFlux facet_flux(const ufcx_form* L_pressure, std::shared_ptr<const dolfinx::fem::FunctionSpace> X,
                     const Domain& domain, const CompiledForms& forms, const Constants& constants);

/// @brief One face of a fault facet as the flow sees it: its side (0: +,
/// 1: -), its + face's vertices' input indices (sorted: the two faces of
/// a facet share them, and they are the fault cell's key,
/// domain/fault_cells.h), its RT0 DOF's global index and its
/// facet flux c = <w.n, 1>.
struct FaceRow
{
  int side = 0;
  std::vector<std::int64_t> key;
  std::int64_t dof = 0;
  double flux = 0;
};

/// The faces of the fault `name` on this rank whose RT0 DOF it owns; `flux`
/// the fault faces' FacetFlux. Z is the flux subspace of a mixed space.
std::vector<FaceRow> fault_face_rows(const Domain& domain, const dolfinx::fem::FunctionSpace& Z,
                                     const std::string& name, std::span<const double> flux);

/// The flux across each "transparent" fault: what leaves the cell on one
/// face enters the cell on the other, c+ z+ + c- z- = 0 for the RT0 DOFs
/// z+- of the two faces of each facet (c their `facet_flux`), tied as
/// z- = -(c+/c-) z+ (tied_dofs.h). With the ties the flux space is the one
/// of the unsplit mesh, so is the flow; the faces are left out of the
/// no-flow condition (flux_bc). Z is the flux subspace of the mixed space.
/// Collective; each tie is given on the rank that owns its z-.
std::vector<Tie> fault_flux_ties(const Scene& scene, const Domain& domain, const dolfinx::fem::FunctionSpace& Z,
                                 const FacetFlux& facet_flux);

} // namespace biotcontact
