#include "diagnostics/diagnostics.h"

#include "assembly/linear_algebra.h"

#include <cmath>
#include <dolfinx/fem/assembler.h>
#include <dolfinx/fem/utils.h>

namespace biotcontact
{
using namespace dolfinx;

namespace
{
double sum_over_ranks(double local, MPI_Comm comm)
{
  double global = 0;
  MPI_Allreduce(&local, &global, 1, MPI_DOUBLE, MPI_SUM, comm);
  return global;
}
} // namespace

ContractionNorm::ContractionNorm(const CompiledForms& forms, std::shared_ptr<const fem::FunctionSpace> V,
                                 std::shared_ptr<const fem::FunctionSpace> Q)
    : _comm(V->mesh()->comm())
{
  _divergence.emplace(assemble_operator(*make_form(forms.a_divergence, {Q, V}, {}, {}), {}));
  _volume = std::make_unique<la::Vector<double>>(Q->dofmap()->index_map, 1);
  add_vector(*_volume, *make_form(forms.L_cell_volume, {Q}, {}, {}));
  _volume->scatter_rev(std::plus<double>());
  _div_du = std::make_unique<la::Vector<double>>(Q->dofmap()->index_map, 1);
  _du = std::make_unique<la::Vector<double>>(V->dofmap()->index_map, V->dofmap()->index_map_bs());
}

double ContractionNorm::operator()(double c_u, std::span<const double> du, double c_p,
                                   std::span<const double> dp)
{
  std::copy(du.begin(), du.end(), _du->mutable_array().begin());
  _div_du->set(0.0);
  multiply_add(_divergence->mat(), *_du, *_div_du); // (D du)_T = |T| div du on T
  const std::span<const double> D = _div_du->array(), volume = _volume->array();
  const std::size_t cells = _volume->map()->size_local();
  double local = 0;
  for (std::size_t T = 0; T < cells; ++T)
  {
    const double w = c_u * D[T] - c_p * volume[T] * dp[T];
    local += w * w / volume[T];
  }
  return std::sqrt(sum_over_ranks(local, _comm));
}

void volumetric_stress(const CompiledForms& forms, const Constants& constants,
                       std::shared_ptr<const fem::Function<double>> u,
                       std::shared_ptr<const fem::Function<double>> p, fem::Function<double>& sigma_v)
{
  auto Q = sigma_v.function_space();
  const fem::Form<double> L = fem::create_form<double>(*forms.L_sigma_v, {Q}, {{"u_out", u}, {"p_out", p}},
                                                       constants, {});
  la::Vector<double>& x = *sigma_v.x();
  x.set(0.0);
  fem::assemble_vector(x.mutable_array(), L);
  x.scatter_rev(std::plus<double>());
  x.scatter_fwd();
}

double relative_error(const ufcx_form& error, const ufcx_form& norm,
                      std::shared_ptr<const fem::Function<double>> f, const std::string& f_name,
                      std::shared_ptr<const fem::Function<double>> reference,
                      const std::string& reference_name)
{
  auto mesh = f->function_space()->mesh();
  const fem::Form<double> E = fem::create_form<double>(
      error, {}, {{f_name, f}, {reference_name, reference}}, Constants{}, {}, mesh);
  const fem::Form<double> N
      = fem::create_form<double>(norm, {}, {{reference_name, reference}}, Constants{}, {}, mesh);
  const double e = sum_over_ranks(fem::assemble_scalar(E), mesh->comm());
  const double n = sum_over_ranks(fem::assemble_scalar(N), mesh->comm());
  return std::sqrt(e / n);
}

double owned_norm(std::span<const double> x, const fem::FunctionSpace& V)
{
  const std::size_t owned = owned_size(V);
  double local = 0;
  for (std::size_t i = 0; i < owned; ++i)
    local += x[i] * x[i];
  return std::sqrt(sum_over_ranks(local, V.mesh()->comm()));
}

} // namespace biotcontact
