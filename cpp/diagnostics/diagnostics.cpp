#include "diagnostics/diagnostics.h"

#include "assembly/linear_algebra.h"

#include <algorithm>
#include <cmath>
#include <limits>
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

ContractionNorm::ContractionNorm(const CompiledForms& forms, const Materials& materials, int q,
                                 std::shared_ptr<const fem::FunctionSpace> V,
                                 std::shared_ptr<const fem::FunctionSpace> Q)
    : _comm(V->mesh()->comm())
{
  const std::vector<double> lambda = materials.on("lmbda", Q), alpha = materials.on("alpha", Q),
                            storage = materials.on("storage", Q), L = materials.on("L", Q);
  const std::size_t n = L.size();
  // Theorem 1 holds with the largest gamma in the norm weighted by
  // lambda_max/lambda_T (docs/theory.md, "Material regions"): the plain
  // norm where lambda is constant, and where some lambda <= 0 (L = "kdr").
  double lambda_max = 0, lambda_min = std::numeric_limits<double>::infinity();
  for (std::size_t T = 0; T < n; ++T)
    lambda_max = std::max(lambda_max, lambda[T]), lambda_min = std::min(lambda_min, lambda[T]);
  MPI_Allreduce(MPI_IN_PLACE, &lambda_max, 1, MPI_DOUBLE, MPI_MAX, _comm);
  MPI_Allreduce(MPI_IN_PLACE, &lambda_min, 1, MPI_DOUBLE, MPI_MIN, _comm);
  std::vector<double> lambda_w(n), alpha_w(n), minus_storage(n);
  _alpha = alpha;
  _alpha_L.resize(n);
  for (std::size_t T = 0; T < n; ++T)
  {
    const double w = lambda_min > 0 ? std::sqrt(lambda_max / lambda[T]) : 1.0;
    lambda_w[T] = lambda[T] * w;
    alpha_w[T] = alpha[T] * w;
    _alpha_L[T] = L[T] > 0 ? alpha[T] / L[T] : 0.0;
    minus_storage[T] = -storage[T];
  }
  _coefficients[Quantity::theorem1] = {lambda_w, alpha_w};
  _coefficients[Quantity::theorem2] = {{}, std::vector<double>(n, 1.0)};
  _coefficients[Quantity::coupled_residual] = {{}, L};
  _coefficients[Quantity::fluid_content] = {alpha, minus_storage};
  set_window_steps(q);

  _divergence.emplace(assemble_operator(*make_form(forms.a_divergence, {Q, V}, {}, {}), {}));
  _volume = std::make_unique<la::Vector<double>>(Q->dofmap()->index_map, 1);
  add_vector(*_volume, *make_form(forms.L_cell_volume, {Q}, {}, {}));
  _volume->scatter_rev(std::plus<double>());
  _div_du = std::make_unique<la::Vector<double>>(Q->dofmap()->index_map, 1);
  _du = std::make_unique<la::Vector<double>>(V->dofmap()->index_map, V->dofmap()->index_map_bs());
}

void ContractionNorm::set_window_steps(int q)
{
  std::vector<double>& alpha_qL = _coefficients[Quantity::theorem2].first;
  std::vector<double>& alpha_q = _coefficients[Quantity::coupled_residual].first;
  alpha_qL.resize(_alpha.size());
  alpha_q.resize(_alpha.size());
  for (std::size_t T = 0; T < _alpha.size(); ++T)
  {
    alpha_qL[T] = _alpha_L[T] / q;
    alpha_q[T] = _alpha[T] / q;
  }
}

double ContractionNorm::operator()(Quantity quantity, std::span<const double> du, std::span<const double> dp)
{
  std::copy(du.begin(), du.end(), _du->mutable_array().begin());
  _div_du->set(0.0);
  multiply_add(_divergence->mat(), *_du, *_div_du); // (D du)_T = |T| div du on T
  return (*this)(quantity, dp);
}

double ContractionNorm::operator()(Quantity quantity, std::span<const double> dp) const
{
  const auto& [c_u, c_p] = _coefficients.at(quantity);
  const std::span<const double> D = _div_du->array(), volume = _volume->array();
  const std::size_t cells = _volume->map()->size_local();
  double local = 0;
  for (std::size_t T = 0; T < cells; ++T)
  {
    const double w = c_u[T] * D[T] - c_p[T] * volume[T] * dp[T];
    local += w * w / volume[T];
  }
  return std::sqrt(sum_over_ranks(local, _comm));
}

void volumetric_stress(const CompiledForms& forms, const Constants& constants, const Materials& materials,
                       std::shared_ptr<const fem::Function<double>> u,
                       std::shared_ptr<const fem::Function<double>> p, fem::Function<double>& sigma_v)
{
  auto Q = sigma_v.function_space();
  Coefficients coefficients = materials.coefficients;
  coefficients.insert({{"u_out", u}, {"p_out", p}});
  const fem::Form<double> L = fem::create_form<double>(*forms.L_sigma_v, {Q}, coefficients, constants, {});
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

} // namespace biotcontact
