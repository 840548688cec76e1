#include "parameters.h"

#include <xtensor/xarray.hpp>
#include <xtensor/xtensor.hpp>

namespace biotcontact
{
using dolfinx::fem::Constant;

Parameters derive_parameters(const Scene& scene)
{
  Parameters P;
  P.d = scene.mesh.dimension;
  P.dt = scene.dt;
  if (scene.mechanics)
  {
    P.G = scene.mechanics->G;
    P.lambda = scene.mechanics->lambda;
    P.K_dr = P.lambda + 2 * P.G / P.d;
  }
  if (scene.flow)
    P.storage = scene.flow->storage();
  if (scene.coupling)
  {
    const CouplingSpec& c = *scene.coupling;
    P.alpha = c.alpha;
    P.q = c.q;
    const double a2 = P.alpha * P.alpha;
    if (c.L_choice == "paper")
      P.L = a2 / P.lambda;
    else if (c.L_choice == "kdr")
      P.L = a2 / P.K_dr;
    else if (c.L_choice == "half-kdr")
      P.L = a2 / (2 * P.K_dr);
    else
      P.L = c.L_number;
    P.gamma = a2 > 0 ? a2 / (a2 + P.lambda * P.storage) : 0.0;
  }
  return P;
}

Constants make_constants(const Scene& scene, const Parameters& P)
{
  auto scalar = [](double v) { return std::make_shared<const Constant<double>>(v); };
  Constants c;
  c["G"] = scalar(P.G);
  c["lmbda"] = scalar(P.lambda);
  c["alpha"] = scalar(P.alpha);
  c["storage"] = scalar(P.storage);
  c["L"] = scalar(P.L);
  c["dt"] = scalar(P.dt);
  c["q"] = scalar(P.q);
  c["ones"] = std::make_shared<const Constant<double>>(std::vector<double>(P.d, 1.0));
  std::vector<double> g(P.d, 0.0);
  double rho_f = 0;
  if (scene.flow and scene.flow->gravity)
  {
    g = *scene.flow->gravity;
    rho_f = *scene.flow->rho_f;
  }
  c["rho_f"] = scalar(rho_f);
  c["gravity"] = std::make_shared<const Constant<double>>(g);
  return c;
}

void interpolate(dolfinx::fem::Function<double>& f, const std::vector<Expression>& components, double t)
{
  const std::size_t n = components.size();
  f.interpolate(
      [&](const xt::xtensor<double, 2>& x) -> xt::xarray<double>
      {
        const std::size_t npts = x.shape(1);
        xt::xarray<double> values = n == 1 ? xt::xarray<double>::from_shape({npts})
                                           : xt::xarray<double>::from_shape({n, npts});
        for (std::size_t j = 0; j < npts; ++j)
          for (std::size_t i = 0; i < n; ++i)
            values.data()[i * npts + j] = components[i](x(0, j), x(1, j), x(2, j), t);
        return values;
      });
}

} // namespace biotcontact
