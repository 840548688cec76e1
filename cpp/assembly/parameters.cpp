#include "assembly/parameters.h"

#include "assembly/node_coordinates.h"

#include <cmath>
#include <stdexcept>
#include <xtensor/xarray.hpp>
#include <xtensor/xbuilder.hpp>
#include <xtensor/xtensor.hpp>

namespace biotcontact
{
using dolfinx::fem::Constant;

namespace
{
/// The parameters of one material: its moduli, storage, alpha (coupling.alpha,
/// or mechanics.alpha of a given pore pressure) and the L that coupling.L
/// chooses for them.
Parameters material_parameters(const Scene& scene, const MechanicsSpec* mechanics, const FlowSpec* flow,
                               double alpha)
{
  Parameters parameters;
  parameters.d = scene.mesh.dimension;
  parameters.dt = scene.dt;
  if (mechanics)
  {
    parameters.G = mechanics->G;
    parameters.lambda = mechanics->lambda;
    parameters.K_dr = parameters.lambda + 2 * parameters.G / parameters.d;
  }
  if (flow)
    parameters.storage = flow->storage();
  parameters.alpha = alpha;
  if (scene.coupling)
  {
    const CouplingSpec& c = *scene.coupling;
    parameters.q = c.q;
    const double a2 = parameters.alpha * parameters.alpha;
    if (c.L_choice == LChoice::paper)
      parameters.L = a2 / parameters.lambda;
    else if (c.L_choice == LChoice::kdr)
      parameters.L = a2 / parameters.K_dr;
    else if (c.L_choice == LChoice::half_kdr)
      parameters.L = a2 / (2 * parameters.K_dr);
    else
      parameters.L = c.L_number;
    parameters.gamma = a2 > 0 ? a2 / (a2 + parameters.lambda * parameters.storage) : 0.0;
  }
  return parameters;
}

const MechanicsSpec* pointer(const std::optional<MechanicsSpec>& m) { return m ? &*m : nullptr; }
const FlowSpec* pointer(const std::optional<FlowSpec>& f) { return f ? &*f : nullptr; }
} // namespace

Parameters derive_parameters(const Scene& scene)
{
  const double alpha = scene.coupling ? scene.coupling->alpha : scene.mechanics ? scene.mechanics->alpha : 0.0;
  return material_parameters(scene, pointer(scene.mechanics), pointer(scene.flow), alpha);
}

Parameters derive_parameters(const Scene& scene, const RegionSpec& region)
{
  return material_parameters(scene, pointer(region.mechanics), pointer(region.flow), region.alpha);
}

Constants make_constants(const Scene& scene, const Parameters& parameters)
{
  auto scalar = [](double v) { return std::make_shared<const Constant<double>>(v); };
  Constants c;
  c["dt"] = scalar(parameters.dt);
  c["q"] = scalar(parameters.q);
  c["ones"] = std::make_shared<const Constant<double>>(std::vector<double>(parameters.d, 1.0));
  std::vector<double> g(parameters.d, 0.0);
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

namespace
{
/// Sets a scalar constant; whether it changed. The forms see the constants
/// as const; the run owns them and may change "dt" and "q" between steps.
bool set_constant(const Constants& constants, const std::string& name, double value)
{
  auto c = std::const_pointer_cast<Constant<double>>(constants.at(name));
  if (c->value[0] == value)
    return false;
  c->value[0] = value;
  return true;
}
} // namespace

bool set_time_step(const Constants& constants, double dt) { return set_constant(constants, "dt", dt); }

bool set_window_steps(const Constants& constants, int q) { return set_constant(constants, "q", q); }

void interpolate(dolfinx::fem::Function<double>& f, const std::vector<Expression>& components, double t)
{
  const std::size_t n = components.size();
  if (on_mesh_nodes(*f.function_space()))
  {
    // At the mesh's own nodes (node_coordinates.h): sqrt(x) is defined at x = 0.
    if (f.function_space()->dofmap()->index_map_bs() != static_cast<int>(n))
      throw std::logic_error("interpolate: one expression per component of the space");
    const std::vector<double> x = node_coordinates(*f.function_space());
    const std::span<double> values = f.x()->mutable_array();
    for (std::size_t node = 0; node < x.size() / 3; ++node)
      for (std::size_t i = 0; i < n; ++i)
        values[n * node + i] = components[i](&x[3 * node], t);
    return;
  }
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

std::vector<double> resistivity(const FlowSpec& flow, int d, const double* x)
{
  std::vector<double> R(d * d, 0.0);
  if (flow.permeability)
  {
    const double k = (*flow.permeability)(x, 0.0);
    if (!(k > 0) or !std::isfinite(k))
      return {};
    for (int i = 0; i < d; ++i)
      R[i * d + i] = flow.mu_f / k;
    return R;
  }
  const std::vector<double>& K = *flow.permeability_tensor;
  if (d == 2)
  {
    const double det = K[0] * K[3] - K[1] * K[2];
    R = {K[3] / det, -K[1] / det, -K[2] / det, K[0] / det};
  }
  else
  {
    const double det = K[0] * (K[4] * K[8] - K[5] * K[7]) - K[1] * (K[3] * K[8] - K[5] * K[6])
                       + K[2] * (K[3] * K[7] - K[4] * K[6]);
    R = {(K[4] * K[8] - K[5] * K[7]) / det, (K[2] * K[7] - K[1] * K[8]) / det,
         (K[1] * K[5] - K[2] * K[4]) / det, (K[5] * K[6] - K[3] * K[8]) / det,
         (K[0] * K[8] - K[2] * K[6]) / det, (K[2] * K[3] - K[0] * K[5]) / det,
         (K[3] * K[7] - K[4] * K[6]) / det, (K[1] * K[6] - K[0] * K[7]) / det,
         (K[0] * K[4] - K[1] * K[3]) / det};
  }
  for (double& r : R)
    r *= flow.mu_f;
  return R;
}

} // namespace biotcontact
