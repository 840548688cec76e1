#include "steps/flow_step.h"

#include "assembly/boundary_conditions.h"

#include <dolfinx/common/Timer.h>
#include <dolfinx/fem/assembler.h>
#include <dolfinx/fem/utils.h>
#include <dolfinx/mesh/utils.h>
#include <algorithm>
#include <xtensor/xarray.hpp>

namespace biotcontact
{
using namespace dolfinx;

FlowStep::FlowStep(const Scene& scene, const Domain& domain, const CompiledForms& forms,
                   const Constants& constants, std::shared_ptr<const fem::FunctionSpace> V)
    : _scene(scene)
{
  const FlowSpec& flow = *scene.flow;
  const auto& mesh = domain.mesh;
  const int d = domain.dim();

  _W = std::make_shared<fem::FunctionSpace>(
      fem::create_functionspace(forms.flow_space, "v_0", mesh));
  {
    auto [Q, map] = _W->sub({1})->collapse();
    _Q = std::make_shared<fem::FunctionSpace>(std::move(Q));
    _Q_to_W = std::move(map);
    auto [Z, zmap] = _W->sub({0})->collapse();
    _Z = std::make_shared<fem::FunctionSpace>(std::move(Z));
    _Z_to_W = std::move(zmap);
  }
  auto R = std::make_shared<fem::Function<double>>(std::make_shared<fem::FunctionSpace>(
      fem::create_functionspace(forms.flow_space, "resistivity", mesh)));
  interpolate_resistivity(*R, flow, d);

  _w = std::make_shared<fem::Function<double>>(_W);
  pressure = std::make_shared<fem::Function<double>>(_Q);
  p_previous = std::make_shared<fem::Function<double>>(_Q);
  p_iterate = std::make_shared<fem::Function<double>>(_Q);
  p_iterate_previous = std::make_shared<fem::Function<double>>(_Q);
  interpolate(*pressure, {flow.initial_pressure}, 0.0);

  // The coupling data are operands of the operators below, not coefficients.
  Coefficients coefficients = {{"resistivity", R}};
  if (V)
  {
    u_iterate = std::make_shared<fem::Function<double>>(V);
    u_window = std::make_shared<fem::Function<double>>(V);
  }
  auto D = std::make_shared<fem::FunctionSpace>(
      fem::create_functionspace(forms.data_space, "source", mesh));
  _source = std::make_shared<fem::Function<double>>(D);
  _p_boundary = std::make_shared<fem::Function<double>>(D);
  coefficients["source"] = _source;
  coefficients["p_boundary"] = _p_boundary;

  auto make = [&](const ufcx_form* f, std::vector<std::shared_ptr<const fem::FunctionSpace>> spaces,
                  const mesh::MeshTags<std::int32_t>* marker = nullptr)
  { return make_form(f, spaces, coefficients, constants, marker); };

  for (const auto& [name, b] : scene.boundaries)
  {
    if (b.flow != BoundarySpec::Flow::pressure)
      continue;
    _markers.push_back(domain.marker(name));
    _L_pressure.emplace_back(&b.pressure, make(forms.L_flow_pressure, {_W}, _markers.back().get()));
    _loads_depend_on_time = _loads_depend_on_time or b.pressure.depends_on_time();
  }
  // No flow (w.n = 0, essential for RT) wherever no pressure is given.
  _bcs.push_back(no_flow_bc(scene, domain, _W->sub({0})));

  _a = make(forms.a_flow, {_W, _W});
  // The terms of the right-hand side that change every coupling iteration,
  // as operators on the iterates (forms/biot.py), assembled once per dt.
  _a_storage = make(forms.a_flow_storage, {_W, _Q});
  _storage.emplace(assemble_operator(*_a_storage, _bcs));
  _dp = std::make_unique<la::Vector<double>>(_Q->dofmap()->index_map, 1);
  const double L = constants.at("L")->value[0];
  if (V and L > 0)
  {
    _a_stabilisation = make(forms.a_flow_stabilisation, {_W, _Q});
    _stabilisation.emplace(assemble_operator(*_a_stabilisation, _bcs));
  }
  if (V)
  {
    _a_displacement = make(forms.a_flow_displacement, {_W, V});
    _displacement.emplace(assemble_operator(*_a_displacement, _bcs));
    _du = std::make_unique<la::Vector<double>>(V->dofmap()->index_map, V->dofmap()->index_map_bs());
  }
  if (flow.source)
  {
    _L_source = make(forms.L_flow_source, {_W});
    _loads_depend_on_time = _loads_depend_on_time or flow.source->depends_on_time();
  }
  if (flow.gravity)
    _L_gravity = make(forms.L_flow_gravity, {_W});

  // The flow matrix depends on dt and L only: assembled and factorised once
  // per dt. Its diagonal blocks, the flux mass and -(S+L)/dt times the cell
  // mass, make it quasi-definite when S + L > 0.
  const double storage = constants.at("storage")->value[0] + L;
  _system = std::make_unique<System>(mesh->comm(), "flow_", _a, _bcs,
                                     storage > 0 ? Structure::quasi_definite : Structure::general,
                                     scene.solver.flow, fields());

  const auto& map = _W->dofmap()->index_map;
  const int bs = _W->dofmap()->index_map_bs();
  _b = std::make_unique<la::Vector<double>>(map, bs);
}

std::vector<Field> FlowStep::fields() const
{
  const auto& map = *_W->dofmap()->index_map; // block size 1
  return {Field{"flux", owned_global_dofs(map, _Z_to_W)}, Field{"pressure", owned_global_dofs(map, _Q_to_W)}};
}

std::span<const double> FlowStep::loads(double t)
{
  // Source, boundary pressure and gravity do not change within a time step:
  // assembled once per time (once per run when they do not depend on t),
  // with the zero no-flow values set (no lifting: they are zero). The
  // loads of the last keep_loads() times are kept: a multirate iteration
  // visits the q fine times of its window again.
  for (const auto& [time, b] : _loads)
    if (time == t or !_loads_depend_on_time)
      return b->array();
  // The oldest entry's vector is reused once the window is full.
  std::unique_ptr<la::Vector<double>> vector;
  if (_loads.size() >= _load_times)
  {
    vector = std::move(_loads.front().second);
    _loads.pop_front();
    vector->set(0.0);
  }
  else
    vector = std::make_unique<la::Vector<double>>(_b->map(), _b->bs());
  _loads.emplace_back(t, std::move(vector));
  la::Vector<double>& b = *_loads.back().second;
  if (_L_source)
  {
    interpolate(*_source, {*_scene.flow->source}, t);
    add_vector(b, *_L_source);
  }
  if (_L_gravity)
    add_vector(b, *_L_gravity);
  for (const auto& [expression, form] : _L_pressure)
  {
    interpolate(*_p_boundary, {*expression}, t);
    add_vector(b, *form);
  }
  b.scatter_rev(std::plus<double>());
  fem::set_bc(b.mutable_array(), _bcs);
  return b.array();
}

void FlowStep::solve(double t)
{
  common::Timer assembly("assembly");
  const std::span<const double> b_loads = loads(t);
  // b = loads - ((S+L)/dt) p^{n+1,m-1} - (L/dt)(p^{n,m} - p^{n,m-1})
  //       + (alpha/(q dt)) div(u^n - u_K), tested with th (forms/biot.py)
  std::copy(b_loads.begin(), b_loads.end(), _b->mutable_array().begin());
  multiply_add(_storage->mat(), *p_previous->x(), *_b);
  if (_stabilisation)
  {
    difference(*p_iterate->x(), *p_iterate_previous->x(), *_dp);
    multiply_add(_stabilisation->mat(), *_dp, *_b);
  }
  if (_displacement)
  {
    difference(*u_iterate->x(), *u_window->x(), *_du);
    multiply_add(_displacement->mat(), *_du, *_b);
  }
  assembly_time += assembly.stop();

  la::petsc::Vector x = wrap(*_w->x()), b = wrap(*_b);
  _system->solve(b.vec(), x.vec());
  _w->x()->scatter_fwd();

  set_unknowns(_w->x()->array());
}

void FlowStep::set_unknowns(std::span<const double> w)
{
  if (w.data() != _w->x()->array().data())
    std::copy(w.begin(), w.end(), _w->x()->mutable_array().begin());
  std::span<double> p = pressure->x()->mutable_array();
  for (std::size_t i = 0; i < _Q_to_W.size(); ++i)
    p[i] = w[_Q_to_W[i]];
}

void FlowStep::time_step_changed()
{
  _system->reassemble();
  common::Timer timer("assembly");
  reassemble_operator(_storage->mat(), *_a_storage, _bcs);
  if (_stabilisation)
    reassemble_operator(_stabilisation->mat(), *_a_stabilisation, _bcs);
  if (_displacement)
    reassemble_operator(_displacement->mat(), *_a_displacement, _bcs);
  assembly_time += timer.stop();
}

void FlowStep::flux(fem::Function<double>& out) const
{
  fem::Function<double> z(_Z);
  std::span<const double> w = _w->x()->array();
  std::span<double> zx = z.x()->mutable_array();
  for (std::size_t i = 0; i < _Z_to_W.size(); ++i)
    zx[i] = w[_Z_to_W[i]];
  // The RT0 field is linear on a cell: its value at the midpoint (the DG0
  // interpolation point) is its cell average.
  out.interpolate(z);
}

} // namespace biotcontact
