// The material coefficients of the forms, cell by cell: the scene's
// top-level values in cells in no region, a region's own in its cells.
#pragma once

#include "assembly/forms.h"
#include "assembly/loads.h"
#include "assembly/parameters.h"
#include "domain/domain.h"

#include <dolfinx/fem/Function.h>
#include <memory>
#include <string>
#include <vector>

namespace biotcontact
{

/// Where the contraction factor gamma = alpha^2/(alpha^2 + lambda S) is
/// largest, over the materials that hold cells: its value and the region
/// that reaches it ("" for the scene's top-level material; on a tie the
/// top-level material, then the first region in name order).
struct GammaPeak
{
  double gamma = 0;
  std::string region;
};

/// Above this gamma the split's contraction theorems guarantee almost
/// nothing (docs/theory.md): the run and `check` warn.
constexpr double high_gamma = 0.99;

/// @brief The material coefficients of forms/biot.py, one value per cell
/// (DG0): G, lmbda, alpha, storage S, the fixed-stress L and the
/// resistivity mu_f K^-1 (a d x d tensor).
///
/// L is cell-wise too: coupling.L = "paper" is alpha_K^2/lambda_K, "kdr"
/// alpha_K^2/K_dr,K, a number the same everywhere (docs/theory.md,
/// "Material regions"). A homogeneous scene has constant coefficients and
/// the same arithmetic as scalar constants.
struct Materials
{
  /// By UFL name: "G", "lmbda", "alpha", "storage", "L", "resistivity".
  Coefficients coefficients;
  /// The parameters of the top-level material and of each region (in the
  /// order of CellRegions::names).
  Parameters top;
  std::vector<Parameters> regions;
  /// Over the materials that hold cells: the largest gamma, the largest L
  /// and the smallest S and S + L (whether the flow matrix is quasi-definite).
  double gamma = 0, max_L = 0, min_storage = 0, min_stabilised_storage = 0;
  /// The region where gamma is reached (GammaPeak).
  std::string gamma_region;
  GammaPeak gamma_peak() const { return {gamma, gamma_region}; }

  /// The same coefficients with L = 0 (the second pass of "multirate-two-pass").
  Materials without_stabilisation() const;

  /// The values of coefficient `name` (a scalar) in the DOF order of the DG0
  /// space Q, ghosts included: the cell-wise coefficients of the contraction
  /// quantities.
  std::vector<double> on(const std::string& name, std::shared_ptr<const dolfinx::fem::FunctionSpace> Q) const;
};

/// @brief The body force term of a step: its two forms on `spaces`, with
/// the nodal coefficient "body_force" (on the P1 space V) and the cell-wise
/// one "body_force_cells".
struct BodyForceTerm
{
  const ufcx_form* nodal;
  const ufcx_form* cellwise;
  std::vector<std::shared_ptr<const dolfinx::fem::FunctionSpace>> spaces;
  std::shared_ptr<const dolfinx::fem::FunctionSpace> V;
};

/// Adds the body force `term` to a step's loads: the scene's body_force
/// interpolated at the nodes into V; when some region gives its own, each
/// cell's material's, one value per cell (DG0), so that a force changes
/// across a region's boundary without smearing over the nodes there.
/// Nothing when no body force is given.
void add_body_force(Loads& loads, const Scene& scene, const Domain& domain, const CompiledForms& forms,
                    const BodyForceTerm& term, const Constants& constants);

/// The largest gamma of the materials `top` (the cells in no region) and
/// `regions` (in the order of cells.names) that hold cells.
GammaPeak largest_gamma(const Parameters& top, const std::vector<Parameters>& regions, const CellRegions& cells);
/// The same from the scene's values (what `check` reads, without the forms).
GammaPeak largest_gamma_of(const Scene& scene, const CellRegions& cells);

/// What to know of a split at this gamma and what converges instead, in
/// one sentence: gamma and the region where it is reached; above
/// high_gamma, that the contraction theorems guarantee almost nothing;
/// then the choices: coupling.scheme = "monolithic", coupling.fallback =
/// "monolithic" for the single-rate split without it, coupling.acceleration = "anderson"
/// unless the scene has it, and below high_gamma
/// more coupling.max_iterations. The one wording of the gamma warning and
/// of the error of a split that did not converge, on both tracks.
std::string split_advice(const GammaPeak& peak, const CouplingSpec& coupling);

/// The warning of a split scene whose gamma exceeds high_gamma, "" for any
/// other (what the run and `check` print).
std::string gamma_warning(const Scene& scene, const GammaPeak& peak);

/// The materials of a scene on its domain; throws SceneError naming the
/// permeability (flow.permeability or region.NAME.permeability) where it is
/// not positive (collective).
Materials make_materials(const Scene& scene, const Domain& domain, const CompiledForms& forms);

/// What make_materials refuses, for `check`: the permeabilities evaluated
/// cell by cell as a run evaluates them (collective; throws SceneError).
void check_materials(const Scene& scene, const Domain& domain);

} // namespace biotcontact
