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

FlowStep::FlowStep(const Problem& problem, std::shared_ptr<const fem::FunctionSpace> V, FlowPass pass)
    : _scene(problem.scene), _pass(pass), _constants(problem.constants)
{
  const Scene& scene = problem.scene;
  const Domain& domain = problem.domain;
  const CompiledForms& forms = problem.forms;
  const Materials& materials = problem.materials;
  const Constants& constants = problem.constants;
  make_spaces(domain, forms, V);
  // The coupling data are operands of the operators below, not coefficients.
  const Coefficients& coefficients = materials.coefficients;
  auto make = [&](const ufcx_form* f, std::vector<std::shared_ptr<const fem::FunctionSpace>> spaces,
                  const mesh::MeshTags<std::int32_t>* marker = nullptr)
  { return make_form(f, spaces, coefficients, constants, marker); };
  // The normal flux (essential for RT) wherever no pressure is given: zero
  // (no flow) but on flux and rate boundaries.
  _bcs.push_back(flux_bc(scene, domain, _W->sub({0}), _fluxes));
  _a = make(forms.a_flow, {_W, _W});
  make_loads(domain, forms, constants);
  make_coupling_operators(forms, make, V, materials.max_L);

  // The flow matrix depends on dt and L only: assembled and factorised once
  // per dt. Its diagonal blocks, the flux mass and -(S+L)/dt times the cell
  // mass, make it quasi-definite when S + L > 0 in every cell.
  const Structure structure
      = materials.min_stabilised_storage > 0 ? Structure::quasi_definite : Structure::general;
  _system = std::make_unique<System>(domain.mesh->comm(), _a, _bcs, SystemLayout{"flow_", structure, fields()},
                                     scene.solver.flow);
  const FacetFlux face_flux = facet_flux(forms.L_flow_pressure, _W, domain, forms, constants);
  _system->tie(fault_flux_ties(scene, domain, *_W->sub({0}), face_flux));
  _b = std::make_unique<la::Vector<double>>(_W->dofmap()->index_map, _W->dofmap()->index_map_bs());
  make_conduits(domain, face_flux, V);
}

void FlowStep::make_conduits(const Domain& domain, const FacetFlux& flux, std::shared_ptr<const fem::FunctionSpace> V)
{
  _conduits = std::make_unique<ConduitFaults>(_scene, domain, *_W->sub({0}), flux);
  if (_pass == FlowPass::second)
    _conduits->without_stabilisation();
  _fault_pressure.assign(_conduits->owned(), 0.0);
  _fault_pressure_previous.assign(_conduits->owned(), 0.0);
  if (!*_conduits)
    return;
  _fault_pressure = _conduits->initial_pressure(_scene.flow->initial_pressure);
  if (V)
    _aperture = std::make_unique<FaultAperture>(_scene, domain, *V);
  append_conduits();
}

void FlowStep::update_apertures()
{
  const std::span<const double> traction = _fault_traction ? *_fault_traction : std::span<const double>();
  if (_conduits->set_openings(_aperture->opening(*u_iterate->x()), traction))
    append_conduits();
}

void FlowStep::append_conduits()
{
  const double dt = _constants.at("dt")->value[0];
  const PetscInt rows = _W->dofmap()->index_map->size_local(); // block size 1
  _system->append({_conduits->exchange(rows), _conduits->operator_matrix(dt), _conduits->face_resistance(),
                   std::vector<double>(_conduits->owned(), 0.0), _fault_pressure});
}

/// The mixed space W = RT0 x P0, its collapsed parts Z and Q with their maps
/// into W, and the functions on them.
void FlowStep::make_spaces(const Domain& domain, const CompiledForms& forms,
                           std::shared_ptr<const fem::FunctionSpace> V)
{
  _W = std::make_shared<fem::FunctionSpace>(fem::create_functionspace(forms.flow_space, "v_0", domain.mesh));
  auto [Q, map] = _W->sub({1})->collapse();
  _Q = std::make_shared<fem::FunctionSpace>(std::move(Q));
  _Q_to_W = std::move(map);
  auto [Z, zmap] = _W->sub({0})->collapse();
  _Z = std::make_shared<fem::FunctionSpace>(std::move(Z));
  _Z_to_W = std::move(zmap);
  _w = std::make_shared<fem::Function<double>>(_W);
  pressure = std::make_shared<fem::Function<double>>(_Q);
  p_previous = std::make_shared<fem::Function<double>>(_Q);
  p_iterate = std::make_shared<fem::Function<double>>(_Q);
  p_iterate_previous = std::make_shared<fem::Function<double>>(_Q);
  p_before = std::make_shared<fem::Function<double>>(_Q);
  interpolate(*pressure, {_scene.flow->initial_pressure}, 0.0);
  if (V)
  {
    u_iterate = std::make_shared<fem::Function<double>>(V);
    u_window = std::make_shared<fem::Function<double>>(V);
    u_before = std::make_shared<fem::Function<double>>(V);
    u_path_before = std::make_shared<fem::Function<double>>(V);
  }
}

/// Source, gravity and boundary pressures (alg. "Flow"), in that order,
/// then the wells, with the prescribed normal fluxes set; a non-zero one is
/// lifted, its column moved to the right-hand side.
void FlowStep::make_loads(const Domain& domain, const CompiledForms& forms, const Constants& constants)
{
  auto D = std::make_shared<fem::FunctionSpace>(fem::create_functionspace(forms.data_space, "source", domain.mesh));
  auto source = std::make_shared<fem::Function<double>>(D), p_boundary = std::make_shared<fem::Function<double>>(D);
  const Coefficients data = {{"source", source}, {"p_boundary", p_boundary}};
  auto make = [&](const ufcx_form* f, const mesh::MeshTags<std::int32_t>* marker = nullptr)
  { return make_form(f, {_W}, data, constants, marker); };
  _loads = std::make_unique<Loads>(_W->dofmap()->index_map, _W->dofmap()->index_map_bs(),
                                   [this](la::Vector<double>& b, double t)
                                   {
                                     add_wells(_wells, t, b.mutable_array());
                                     update(_fluxes, t);
                                     if (!_fluxes.boundaries.empty())
                                       return finish_rhs(b, _a, _bcs);
                                     b.scatter_rev(std::plus<double>());
                                     fem::set_bc(b.mutable_array(), _bcs);
                                   });
  for (const FluxBoundary& f : _fluxes.boundaries)
    _loads->depends_on_time((f.rate ? f.rate : f.flux)->depends_on_time());
  _wells = well_sources(_scene, domain, *_Q, _Q_to_W);
  _loads->depends_on_time(depends_on_time(_wells));
  const FlowSpec& flow = *_scene.flow;
  if (flow.source)
    _loads->add(make(forms.L_flow_source), source, {*flow.source});
  if (flow.gravity)
    _loads->add(make(forms.L_flow_gravity));
  for (const auto& [name, b] : _scene.boundaries)
    if (b.flow == BoundarySpec::Flow::pressure)
      _loads->add_boundary(
          domain, name, [&](const mesh::MeshTags<std::int32_t>* marker) { return make(forms.L_flow_pressure, marker); },
          p_boundary, {b.pressure});
  for (const auto& [name, f] : _scene.faults)
    if (f.flow == FaultFlow::pressure) // the faces hold the fault's pressure
    {
      auto pressure = std::make_shared<fem::Function<double>>(D);
      const Coefficients face = {{"p_boundary", pressure}};
      _loads->add_on_facets(
          domain.fault_faces(name), [&](const mesh::MeshTags<std::int32_t>* marker)
          { return make_form(forms.L_flow_pressure, {_W}, face, constants, marker); }, pressure, {*f.pressure});
    }
}

/// The terms of the right-hand side that change every coupling iteration,
/// as operators on the iterates (forms/biot.py), assembled once per dt: the
/// storage term, the stabilisation L (coupled scenes with L > 0) and the
/// displacement term (coupled scenes).
template <class Make>
void FlowStep::make_coupling_operators(const CompiledForms& forms, const Make& make,
                                       std::shared_ptr<const fem::FunctionSpace> V, double L)
{
  _a_storage = make(forms.a_flow_storage, {_W, _Q}, nullptr);
  _storage.emplace(assemble_operator(*_a_storage, _bcs));
  _dp = std::make_unique<la::Vector<double>>(_Q->dofmap()->index_map, 1);
  if (!V)
    return;
  if (L > 0)
  {
    _a_stabilisation = make(forms.a_flow_stabilisation, {_W, _Q}, nullptr);
    _stabilisation.emplace(assemble_operator(*_a_stabilisation, _bcs));
  }
  _a_displacement = make(forms.a_flow_displacement, {_W, V}, nullptr);
  _displacement.emplace(assemble_operator(*_a_displacement, _bcs));
  _du = std::make_unique<la::Vector<double>>(V->dofmap()->index_map, V->dofmap()->index_map_bs());
}

std::vector<Field> FlowStep::fields() const
{
  const auto& map = *_W->dofmap()->index_map; // block size 1
  return {Field{"flux", owned_global_dofs(map, _Z_to_W)}, Field{"pressure", owned_global_dofs(map, _Q_to_W)}};
}

void FlowStep::solve(double t)
{
  common::Timer assembly("assembly");
  const std::span<const double> b_loads = _loads->at(t).array();
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
  if (_aperture and _fine_step == 1)
    update_apertures();
  if (*_conduits)
  {
    _conduits->load(fine_step(t), _fault_pressure_previous, _fault_pressure, _system->appended().b);
    _system->appended().x = _fault_pressure;
  }
  assembly_time += assembly.stop();

  la::petsc::Vector x = wrap(*_w->x()), b = wrap(*_b);
  _system->solve(b.vec(), x.vec());
  _w->x()->scatter_fwd();
  if (*_conduits)
    _fault_pressure = _system->appended().x;

  set_unknowns(_w->x()->array());
}

std::span<const double> FlowStep::unknowns() const
{
  if (!*_conduits)
    return _w->x()->array();
  _unknowns.assign(_w->x()->array().begin(), _w->x()->array().end());
  _unknowns.insert(_unknowns.end(), _fault_pressure.begin(), _fault_pressure.end());
  return _unknowns;
}

void FlowStep::set_unknowns(std::span<const double> w)
{
  const std::size_t n = _w->x()->array().size();
  if (w.size() > n)
    std::copy(w.begin() + n, w.end(), _fault_pressure.begin());
  if (w.data() != _w->x()->array().data())
    std::copy_n(w.begin(), n, _w->x()->mutable_array().begin());
  std::span<double> p = pressure->x()->mutable_array();
  for (std::size_t i = 0; i < _Q_to_W.size(); ++i)
    p[i] = w[_Q_to_W[i]];
}

void FlowStep::time_step_changed()
{
  _system->reassemble();
  if (*_conduits)
    append_conduits();
  common::Timer timer("assembly");
  reassemble_operator(_storage->mat(), *_a_storage, _bcs);
  if (_stabilisation)
    reassemble_operator(_stabilisation->mat(), *_a_stabilisation, _bcs);
  if (_displacement)
    reassemble_operator(_displacement->mat(), *_a_displacement, _bcs);
  assembly_time += timer.stop();
}

void FlowStep::window_steps_changed()
{
  if (!_displacement)
    return;
  common::Timer timer("assembly");
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

void FlowStep::advance(double t, const TimeDerivative& d)
{
  _derivative = d;
  assign(*p_previous, history_value(d, pressure->x()->array(), p_before->x()->array()));
  recorded_solve(true, [&] { solve(t); });
}

std::map<std::string, std::vector<double>> FlowStep::arrays() const
{
  if (!*_conduits or _pass == FlowPass::second)
    return {};
  return _conduits->arrays(_fault_pressure);
}

void FlowStep::restore_arrays(const std::map<std::string, std::vector<double>>& arrays)
{
  if (!*_conduits or _pass == FlowPass::second)
    return;
  _conduits->restore_arrays(arrays, _fault_pressure);
}

std::vector<double> FlowStep::fault_flow(double t) const
{
  if (!*_conduits)
    return {};
  return _conduits->cell_values(_w->x()->array(), _fault_pressure, t);
}

StepState FlowStep::state() const { return {values(unknowns()), values(pressure->x()->array()), {}}; }

void FlowStep::keep_history(const StepState& start) { assign(*p_before, start.p); }

void FlowStep::accept(double t)
{
  if (*_conduits and _pass == FlowPass::first)
  {
    _conduits->add_volumes(
        _conduits->step_volumes(_w->x()->array(), _fault_pressure, _fault_pressure_previous, fine_step(t)),
        fine_step(t), _fault_pressure_previous);
    _conduits->set_intersection_rates(_fault_pressure);
  }
}

std::string FlowStep::unbalanced(double t) const
{
  if (!*_conduits or _pass == FlowPass::second)
    return {};
  const std::span<const double> w = _w->x()->array();
  return _conduits->unbalanced(_conduits->step_volumes(w, _fault_pressure, _fault_pressure_previous, fine_step(t)),
                               largest_entry(w, _Z_to_W, _W->mesh()->comm()));
}

FineStep FlowStep::fine_step(double t) const
{
  return {t, _constants.at("dt")->value[0], _fine_step, static_cast<int>(_constants.at("q")->value[0]),
          _derivative.coefficients()};
}

void FlowStep::set_fine_step(int m, std::span<const double> previous, std::span<const double> iterate)
{
  _fine_step = m;
  _fault_pressure_previous.assign(previous.begin(), previous.end());
  _fault_pressure.assign(iterate.begin(), iterate.end());
}

History FlowStep::history() const
{
  History h;
  if (_pass == FlowPass::second)
    return h;
  const bool bdf2 = _scene.time_scheme == TimeScheme::bdf2, q_auto = _scene.coupling and _scene.coupling->q_auto;
  if (bdf2)
    h.push_back({"pressure_before", p_before.get()});
  if ((bdf2 or q_auto) and u_before)
    h.push_back({"displacement_before", u_before.get()});
  if (bdf2 and u_before)
    h.push_back({"displacement_path_before", u_path_before.get()});
  return h;
}

} // namespace biotcontact
