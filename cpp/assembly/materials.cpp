#include "assembly/materials.h"

#include <algorithm>
#include <dolfinx/fem/utils.h>
#include <iomanip>
#include <limits>
#include <sstream>
#include <xtensor/xarray.hpp>
#include <xtensor/xtensor.hpp>

namespace biotcontact
{
using namespace dolfinx;

namespace
{
using Function = fem::Function<double>;

/// Interpolates into a DG0 function a value per cell: `value(cell, x, out)`
/// writes the components at the cell's midpoint x (dolfinx interpolates into
/// DG0 at one point per cell, the cells in their local order).
void set_per_cell(Function& f, int components, const std::function<void(std::size_t, const double*, double*)>& value)
{
  f.interpolate(
      [&](const xt::xtensor<double, 2>& x) -> xt::xarray<double>
      {
        const std::size_t n = x.shape(1);
        xt::xarray<double> v = components == 1 ? xt::xarray<double>::from_shape({n})
                                               : xt::xarray<double>::from_shape({std::size_t(components), n});
        std::vector<double> point(3), out(components);
        for (std::size_t j = 0; j < n; ++j)
        {
          for (int i = 0; i < 3; ++i)
            point[i] = x(i, j);
          value(j, point.data(), out.data());
          for (int i = 0; i < components; ++i)
            v.data()[i * n + j] = out[i];
        }
        return v;
      });
}

/// mu_f K^-1 cell by cell; the key of the first permeability that is not
/// positive on this rank, or an empty string.
std::string set_resistivity(Function& R, const Scene& scene, const CellRegions& cells, int d)
{
  std::vector<const FlowSpec*> flows;
  for (const std::string& name : cells.names)
    flows.push_back(&*scene.regions.at(name).flow);
  std::string error;
  set_per_cell(R, d * d,
               [&](std::size_t c, const double* x, double* out)
               {
                 const int r = cells.region[c];
                 const std::vector<double> values = resistivity(r < 0 ? *scene.flow : *flows[r], d, x);
                 if (values.empty() and error.empty())
                 {
                   std::ostringstream where;
                   where << (r < 0 ? "flow" : "region." + cells.names[r]) << ".permeability: must be positive at ("
                         << x[0] << ", " << x[1];
                   if (d == 3)
                     where << ", " << x[2];
                   where << ")";
                   error = scene.file + ": " + where.str();
                 }
                 std::copy_n(values.empty() ? std::vector<double>(d * d, 1.0).data() : values.data(), d * d, out);
               });
  return error;
}

/// Over the materials that hold cells: the largest gamma and L, the smallest S + L.
void summarise(Materials& m, const CellRegions& cells)
{
  std::vector<const Parameters*> used;
  if (cells.outside > 0)
    used.push_back(&m.top);
  for (std::size_t r = 0; r < m.regions.size(); ++r)
    used.push_back(&m.regions[r]);
  const GammaPeak peak = largest_gamma(m.top, m.regions, cells);
  m.gamma = peak.gamma;
  m.gamma_region = peak.region;
  m.max_L = 0;
  m.min_storage = m.min_stabilised_storage = std::numeric_limits<double>::infinity();
  for (const Parameters* p : used)
  {
    m.max_L = std::max(m.max_L, p->L);
    m.min_storage = std::min(m.min_storage, p->storage);
    m.min_stabilised_storage = std::min(m.min_stabilised_storage, p->storage + p->L);
  }
}
} // namespace

GammaPeak largest_gamma(const Parameters& top, const std::vector<Parameters>& regions, const CellRegions& cells)
{
  GammaPeak peak;
  if (cells.outside > 0)
    peak.gamma = top.gamma;
  for (std::size_t r = 0; r < regions.size(); ++r)
    if (regions[r].gamma > peak.gamma)
      peak = {regions[r].gamma, cells.names[r]};
  return peak;
}

GammaPeak largest_gamma_of(const Scene& scene, const CellRegions& cells)
{
  std::vector<Parameters> regions;
  for (const std::string& name : cells.names)
    regions.push_back(derive_parameters(scene, scene.regions.at(name)));
  return largest_gamma(derive_parameters(scene), regions, cells);
}

std::string split_advice(const GammaPeak& peak, const CouplingSpec& coupling)
{
  std::ostringstream advice;
  advice << "gamma = " << std::setprecision(7) << peak.gamma;
  if (!peak.region.empty())
    advice << " in region " << peak.region;
  if (peak.gamma > high_gamma)
    advice << " > " << high_gamma << ": the contraction theorems guarantee almost nothing, expect many coupling "
           << "iterations or none converging";
  // docs/theory.md, "Anderson acceleration": its iterates are not bound to
  // contract by gamma each.
  advice << "; instead: coupling.scheme = \"monolithic\" (no coupling iteration: the robust choice)";
  if (coupling.scheme != CouplingScheme::monolithic and coupling.fallback == Fallback::none)
    advice << ", coupling.fallback = \"monolithic\" (that scheme for the steps the split fails at)";
  if (coupling.acceleration != Acceleration::anderson)
    advice << ", coupling.acceleration = \"anderson\" (not bound to gamma per iteration)";
  if (peak.gamma <= high_gamma)
    advice << ", a larger coupling.max_iterations (each iteration contracts by gamma or better)";
  return advice.str();
}

std::string gamma_warning(const Scene& scene, const GammaPeak& peak)
{
  if (!scene.coupling or scene.coupling->scheme == CouplingScheme::monolithic or peak.gamma <= high_gamma)
    return "";
  return split_advice(peak, *scene.coupling);
}

Materials make_materials(const Scene& scene, const Domain& domain, const CompiledForms& forms)
{
  Materials m;
  m.top = derive_parameters(scene);
  for (const std::string& name : domain.regions.names)
    m.regions.push_back(derive_parameters(scene, scene.regions.at(name)));
  summarise(m, domain.regions);
  auto Q = std::make_shared<fem::FunctionSpace>(fem::create_functionspace(forms.material_space, "G", domain.mesh));
  const std::vector<std::int32_t>& region = domain.regions.region;
  const std::pair<const char*, double Parameters::*> scalars[]
      = {{"G", &Parameters::G}, {"lmbda", &Parameters::lambda}, {"alpha", &Parameters::alpha},
         {"storage", &Parameters::storage}, {"L", &Parameters::L}};
  for (const auto& [name, member] : scalars)
  {
    auto f = std::make_shared<Function>(Q);
    set_per_cell(*f, 1, [&, member = member](std::size_t c, const double*, double* out)
                 { *out = region[c] < 0 ? m.top.*member : m.regions[region[c]].*member; });
    m.coefficients[name] = f;
  }
  auto R = std::make_shared<Function>(std::make_shared<fem::FunctionSpace>(
      fem::create_functionspace(forms.flow_space, "resistivity", domain.mesh)));
  if (scene.flow)
    agree_on_error(set_resistivity(*R, scene, domain.regions, domain.dim()), domain.mesh->comm());
  m.coefficients["resistivity"] = R;
  return m;
}

void check_materials(const Scene& scene, const Domain& domain)
{
  make_materials(scene, domain, compiled_forms(domain.mesh->topology().cell_type()));
}

namespace
{
/// Each cell's body force at time t: its material's, zero where none is given.
void set_body_force(Function& f, const Scene& scene, const CellRegions& cells, int d, double t)
{
  std::vector<const std::optional<std::vector<Expression>>*> forces = {&scene.mechanics->body_force};
  for (const std::string& name : cells.names)
    forces.push_back(&scene.regions.at(name).mechanics->body_force);
  set_per_cell(f, d,
               [&](std::size_t c, const double* x, double* out)
               {
                 const auto& force = *forces[cells.region[c] + 1];
                 for (int i = 0; i < d; ++i)
                   out[i] = force ? (*force)[i](x, t) : 0.0;
               });
}
} // namespace

void add_body_force(Loads& loads, const Scene& scene, const Domain& domain, const CompiledForms& forms,
                    const BodyForceTerm& term, const Constants& constants)
{
  const auto& [nodal, cellwise, spaces, V] = term;
  if (!scene.cellwise_body_force())
  {
    if (!scene.mechanics->body_force)
      return;
    auto f = std::make_shared<Function>(V);
    loads.add(make_form(nodal, spaces, {{"body_force", f}}, constants), f, *scene.mechanics->body_force);
    return;
  }
  auto f = std::make_shared<Function>(std::make_shared<fem::FunctionSpace>(
      fem::create_functionspace(forms.cell_vector_space, "body_force_cells", domain.mesh)));
  bool time_dependent = false;
  const auto depends_on_time = [&](const std::optional<std::vector<Expression>>& force)
  {
    for (const Expression& e : force.value_or(std::vector<Expression>{}))
      time_dependent = time_dependent or e.depends_on_time();
  };
  depends_on_time(scene.mechanics->body_force);
  for (const auto& [name, region] : scene.regions)
    depends_on_time(region.mechanics->body_force);
  const int d = domain.dim();
  loads.add(make_form(cellwise, spaces, {{"body_force_cells", f}}, constants), f,
            [&scene, &cells = domain.regions, d](Function& g, double t) { set_body_force(g, scene, cells, d, t); },
            time_dependent);
}

Materials Materials::without_stabilisation() const
{
  Materials m = *this;
  auto L = std::make_shared<Function>(coefficients.at("L")->function_space());
  m.coefficients["L"] = L; // zero
  m.top.L = 0;
  for (Parameters& p : m.regions)
    p.L = 0;
  m.max_L = 0;
  m.min_stabilised_storage = min_storage;
  return m;
}

std::vector<double> Materials::on(const std::string& name, std::shared_ptr<const fem::FunctionSpace> Q) const
{
  Function f(Q);
  f.interpolate(*coefficients.at(name));
  const std::span<const double> x = f.x()->array();
  return std::vector<double>(x.begin(), x.end());
}

} // namespace biotcontact
