#include "diagnostics/reference_errors.h"

#include "assembly/linear_algebra.h"
#include "diagnostics/closed_form.h"
#include "diagnostics/diagnostics.h"

#include <cmath>
#include <dolfinx/fem/utils.h>
#include <functional>
#include <xtensor/xarray.hpp>

namespace biotcontact
{
using namespace dolfinx;

namespace
{

/// Mean of one displacement component over the nodes of one boundary
/// (collective).
double boundary_mean(const fem::Function<double>& u, const std::vector<std::int32_t>& facets, int component)
{
  const auto& V = *u.function_space();
  const auto dofs = fem::locate_dofs_topological(*V.sub({component}), V.mesh()->topology().dim() - 1, facets);
  const std::int32_t owned = owned_size(V);
  double local[2] = {0, 0};
  for (std::int32_t dof : dofs)
    if (dof < owned)
    {
      local[0] += u.x()->array()[dof];
      local[1] += 1;
    }
  double global[2];
  MPI_Allreduce(local, global, 2, MPI_DOUBLE, MPI_SUM, V.mesh()->comm());
  return global[0] / global[1];
}

/// The closed form at the end time: pressure and displacement at (x, y).
struct ClosedForm
{
  std::function<double(double, double)> p;
  std::function<std::array<double, 2>(double, double)> u;
};

/// The closed form interpolated into the P2 space of the coefficient
/// `name` of the error forms ("p_reference" or "u_reference"): `value(x, y,
/// v, j)` sets column j of v, the value at point j.
template <class Value>
std::shared_ptr<fem::Function<double>> interpolated(const Problem& problem, CompiledForms::SpaceFactory space,
                                                    const char* name, std::vector<std::size_t> shape, Value value)
{
  auto f = std::make_shared<fem::Function<double>>(
      std::make_shared<fem::FunctionSpace>(fem::create_functionspace(space, name, problem.domain.mesh)));
  f->interpolate(
      [&](const xt::xtensor<double, 2>& x) -> xt::xarray<double>
      {
        shape.back() = x.shape(1);
        xt::xarray<double> v = xt::zeros<double>(shape);
        for (std::size_t j = 0; j < x.shape(1); ++j)
          value(x(0, j), x(1, j), v, j);
        return v;
      });
  return f;
}

} // namespace

ReferenceErrors reference_errors(const Problem& problem, std::shared_ptr<const fem::Function<double>> u,
                                 std::shared_ptr<const fem::Function<double>> p)
{
  const Scene& scene = problem.scene;
  const Parameters& m = problem.parameters;
  const ReferenceSpec& ref = *scene.reference;
  const FlowSpec& fs = *scene.flow;
  const double mobility = (*fs.permeability)(0, 0, 0, 0) / fs.mu_f;
  const double t = scene.end_time, y0 = scene.mesh.lower[1];
  ClosedForm exact;
  std::optional<Terzaghi> terzaghi;
  std::optional<Mandel> mandel;
  if (ref.solution == ReferenceSolution::terzaghi)
  {
    terzaghi.emplace(Terzaghi{ref.height, m.G, m.lambda, m.alpha, m.storage, mobility, ref.load});
    exact.p = [&](double, double y) { return terzaghi->pressure(y - y0, t); };
    exact.u = [&](double, double y) { return std::array<double, 2>{0.0, terzaghi->displacement(y - y0, t)}; };
  }
  else
  {
    mandel.emplace(scene.mesh.upper[0], scene.mesh.upper[1], Medium{m.G, m.lambda, m.alpha, m.storage, mobility},
                   ref.force);
    exact.p = [&](double x, double) { return mandel->pressure(x, t); };
    exact.u = [&](double x, double y) { return std::array<double, 2>{mandel->displacement_x(x, t), mandel->displacement_y(y, t)}; };
  }
  const CompiledForms& forms = problem.forms;
  auto p_ref = interpolated(problem, forms.pressure_reference_space, "p_reference", {0},
                            [&](double x, double y, auto& v, std::size_t j) { v(j) = exact.p(x, y); });
  const std::size_t d = problem.domain.dim();
  auto u_ref = interpolated(problem, forms.displacement_reference_space, "u_reference", {d, 0},
                            [&](double x, double y, auto& v, std::size_t j)
                            {
                              const auto uj = exact.u(x, y);
                              v(0, j) = uj[0];
                              v(1, j) = uj[1];
                            });
  ReferenceErrors errors;
  errors.time = t;
  errors.pressure_rel_l2
      = relative_error(*forms.M_pressure_error, *forms.M_pressure_reference, p, "p_out", p_ref, "p_reference");
  errors.displacement_rel_l2 = relative_error(*forms.M_displacement_error, *forms.M_displacement_reference, u,
                                              "u_out", u_ref, "u_reference");
  if (terzaghi)
  {
    const double settlement = -boundary_mean(*u, problem.domain.boundaries.at("top"), 1);
    const double exact_settlement = terzaghi->settlement(t);
    errors.settlement = ReferenceErrors::Settlement{
        settlement, exact_settlement, std::abs(settlement - exact_settlement) / std::abs(exact_settlement)};
  }
  return errors;
}

} // namespace biotcontact
