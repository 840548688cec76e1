// Quantities measured on a run: the contraction quantities of Theorems 1
// and 2, the volumetric stress for output, and errors against closed forms.
// All are collective (every rank calls them).
#pragma once

#include "assembly/forms.h"
#include "assembly/materials.h"
#include "assembly/parameters.h"

#include <dolfinx/fem/Form.h>
#include <dolfinx/fem/Function.h>
#include <dolfinx/la/Vector.h>
#include <dolfinx/la/petsc.h>
#include <map>
#include <optional>
#include <memory>
#include <span>

namespace biotcontact
{

/// @brief The norms ||c_u div(du) - c_p dp||_L2 of the coupling, with
/// cell-wise coefficients c_u and c_p from the materials of the cells.
///
/// The quantities (docs/theory.md, "The theorems' quantities"):
/// - theorem1: c_u = lambda w, c_p = alpha w (delta sigma_v of Theorem 1,
///   weighted by w = sqrt(lambda_max/lambda), in which norm the theorem
///   holds with the largest gamma; w = 1 where lambda is constant);
/// - theorem2: c_u = alpha/(q L), c_p = 1 (Theorem 2; 0 where L = 0);
/// - coupled_residual: c_u = alpha/q, c_p = L (L times Theorem 2's
///   quantity: what the flow equations miss with u^n for u^{n+1});
/// - fluid_content: c_u = alpha, c_p = -S (the change alpha div u + S p).
/// For P1 du and P0 dp the integrand is constant on a cell, so with D the
/// operator of the cell integrals of div (a_divergence, assembled once) and
/// |T| the cell volumes (L_cell_volume),
///     ||c_u div du - c_p dp||^2 = sum_T (c_u,T (D du)_T - c_p,T |T| dp_T)^2 / |T|
/// exactly: one product per du and one pass over the cells per norm.
class ContractionNorm
{
public:
  enum class Quantity
  {
    theorem1,
    theorem2,
    coupled_residual,
    fluid_content
  };

  ContractionNorm(const CompiledForms& forms, const Materials& materials, int q,
                  std::shared_ptr<const dolfinx::fem::FunctionSpace> V,
                  std::shared_ptr<const dolfinx::fem::FunctionSpace> Q);
  /// The norm of `quantity` with the displacement increment du and the
  /// pressure increment dp (DOF arrays with ghosts of V and Q).
  double operator()(Quantity quantity, std::span<const double> du, std::span<const double> dp);
  /// The same with the du of the last call (D du is kept).
  double operator()(Quantity quantity, std::span<const double> dp) const;
  /// The coefficients of theorem2 and coupled_residual for windows of q
  /// fine steps (coupling.q = "auto" changes q between windows).
  void set_window_steps(int q);

private:
  MPI_Comm _comm;
  std::vector<double> _alpha, _alpha_L; // alpha and alpha/L (0 where L = 0) per cell
  std::optional<dolfinx::la::petsc::Matrix> _divergence; // Q x V
  std::unique_ptr<dolfinx::la::Vector<double>> _volume, _du, _div_du;
  std::map<Quantity, std::pair<std::vector<double>, std::vector<double>>> _coefficients; // (c_u, c_p) per cell
};

/// sigma_v = lambda div u - alpha p in each cell (L_sigma_v).
void volumetric_stress(const CompiledForms& forms, const Constants& constants, const Materials& materials,
                       std::shared_ptr<const dolfinx::fem::Function<double>> u,
                       std::shared_ptr<const dolfinx::fem::Function<double>> p,
                       dolfinx::fem::Function<double>& sigma_v);

/// Relative L2 error ||f - reference|| / ||reference|| with the compiled
/// forms; `reference` lives in P2.
double relative_error(const ufcx_form& error, const ufcx_form& norm,
                      std::shared_ptr<const dolfinx::fem::Function<double>> f, const std::string& f_name,
                      std::shared_ptr<const dolfinx::fem::Function<double>> reference,
                      const std::string& reference_name);

} // namespace biotcontact
