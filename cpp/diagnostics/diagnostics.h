// Quantities measured on a run: the contraction quantities of Theorems 1
// and 2, the volumetric stress for output, and errors against closed forms.
// All are collective (every rank calls them).
#pragma once

#include "assembly/forms.h"
#include "assembly/parameters.h"

#include <dolfinx/fem/Form.h>
#include <dolfinx/fem/Function.h>
#include <dolfinx/la/Vector.h>
#include <dolfinx/la/petsc.h>
#include <optional>
#include <memory>
#include <span>

namespace biotcontact
{

/// ||c_u div(du) - c_p dp||_L2, measured every coupling iteration. For P1
/// du and P0 dp the integrand is constant on a cell, so with D the operator
/// of the cell integrals of div (a_divergence, assembled once) and |T| the
/// cell volumes (L_cell_volume),
///     ||c_u div du - c_p dp||^2 = sum_T (c_u (D du)_T - c_p |T| dp_T)^2 / |T|
/// exactly: one product and one pass over the cells.
class ContractionNorm
{
public:
  ContractionNorm(const CompiledForms& forms, std::shared_ptr<const dolfinx::fem::FunctionSpace> V,
                  std::shared_ptr<const dolfinx::fem::FunctionSpace> Q);
  /// du and dp are DOF arrays (with ghosts) of the displacement and pressure spaces.
  double operator()(double c_u, std::span<const double> du, double c_p, std::span<const double> dp);

private:
  MPI_Comm _comm;
  std::optional<dolfinx::la::petsc::Matrix> _divergence; // Q x V
  std::unique_ptr<dolfinx::la::Vector<double>> _volume, _du, _div_du;
};

/// sigma_v = lambda div u - alpha p in each cell (L_sigma_v).
void volumetric_stress(const CompiledForms& forms, const Constants& constants,
                       std::shared_ptr<const dolfinx::fem::Function<double>> u,
                       std::shared_ptr<const dolfinx::fem::Function<double>> p,
                       dolfinx::fem::Function<double>& sigma_v);

/// Relative L2 error ||f - reference|| / ||reference|| with the compiled
/// forms; `reference` lives in P2.
double relative_error(const ufcx_form& error, const ufcx_form& norm,
                      std::shared_ptr<const dolfinx::fem::Function<double>> f, const std::string& f_name,
                      std::shared_ptr<const dolfinx::fem::Function<double>> reference,
                      const std::string& reference_name);

/// Euclidean norm of the owned part of a DOF array (collective).
double owned_norm(std::span<const double> x, const dolfinx::fem::FunctionSpace& V);

} // namespace biotcontact
