#include "steps/monolithic_step.h"

#include "assembly/boundary_conditions.h"
#include "steps/mechanics_step.h"

#include <dolfinx/common/Timer.h>
#include <dolfinx/fem/assembler.h>
#include <algorithm>
#include <dolfinx/fem/utils.h>
#include <iterator>
#include <stdexcept>

namespace biotcontact
{
using namespace dolfinx;

namespace
{
/// The collapsed subspace i of X and the map from its DOFs to X's.
std::shared_ptr<const fem::FunctionSpace> collapse(const fem::FunctionSpace& X, int i,
                                                   std::vector<std::int32_t>& map)
{
  auto [space, m] = X.sub({i})->collapse();
  map = std::move(m);
  return std::make_shared<fem::FunctionSpace>(std::move(space));
}

void extract(const fem::Function<double>& x, const std::vector<std::int32_t>& map, fem::Function<double>& part)
{
  std::span<const double> from = x.x()->array();
  std::span<double> to = part.x()->mutable_array();
  for (std::size_t i = 0; i < map.size(); ++i)
    to[i] = from[map[i]];
}
} // namespace

MonolithicStep::MonolithicStep(const Problem& problem) : _problem(problem), _scene(problem.scene)
{
  const Scene& scene = problem.scene;
  const Domain& domain = problem.domain;
  const CompiledForms& forms = problem.forms;
  const Materials& materials = problem.materials;
  const Constants& constants = problem.constants;
  make_spaces(domain, forms);
  Coefficients coefficients = materials.coefficients;
  coefficients.insert({{"p_old", _p_old}, {"u_old", _u_old}});
  // Essential conditions: displacement components on X.sub(0), no flow on X.sub(1).
  _bcs = displacement_bcs(scene, domain, _X->sub({0}), _bc_values);
  _bcs.push_back(flux_bc(scene, domain, _X->sub({1}), _fluxes));
  // The faces the pore pressure loads, for the face term of the operator.
  const auto faces = pore_pressure_faces(scene, domain);
  _a = make_form(forms.a_monolithic, {_X, _X}, coefficients, constants, faces.get());
  _L_history = make_form(forms.L_monolithic_history, {_X}, coefficients, constants);
  make_loads(domain, forms, constants);

  // The coupled matrix depends on dt only: assembled and factorised once per
  // dt (and per inactive set with contact). Its pressure block -(S/dt) times
  // the cell mass is often negligible against the coupling (S = 1e-12 in the
  // poroelastic Hertz scene): LU with pivoting. The iterative path is a
  // Krylov method preconditioned by the fixed-stress split (solver.h),
  // built from a_monolithic_preconditioner and split along fields() (the
  // conduit faults' p_f joins the flow: System::append).
  _system = std::make_unique<System>(domain.mesh->comm(), _a, _bcs,
                                     SystemLayout{"monolithic_", Structure::general, fields()},
                                     scene.solver.monolithic,
                                     make_form(forms.a_monolithic_preconditioner, {_X, _X}, coefficients, constants,
                                               faces.get()));
  const FacetFlux flux = facet_flux(forms.L_monolithic_pressure, _X, domain, forms, constants);
  _system->tie(fault_flux_ties(scene, domain, *_X->sub({1}), flux));
  _b = std::make_unique<la::Vector<double>>(_X->dofmap()->index_map, _X->dofmap()->index_map_bs());
  // p_f before the contact: the contact solver takes the appended system.
  _conduits = std::make_unique<MonolithicConduits>(problem, MixedSpace{*_X, *V, _V_to_X, _bcs, flux});
  if (*_conduits)
    _conduits->append(*_system);
  if (scene.has_contact())
    attach_contact(domain, forms);
}

/// The mixed space X = P1^d x RT0 x P0, its collapsed parts with their maps
/// into X, and the unknown, started from the initial state (the guess of a
/// contact solve).
void MonolithicStep::make_spaces(const Domain& domain, const CompiledForms& forms)
{
  _X = std::make_shared<fem::FunctionSpace>(fem::create_functionspace(forms.monolithic_space, "v_0", domain.mesh));
  V = collapse(*_X, 0, _V_to_X);
  _Z = collapse(*_X, 1, _Z_to_X);
  Q = collapse(*_X, 2, _Q_to_X);
  _x = std::make_shared<fem::Function<double>>(_X);
  u = std::make_shared<fem::Function<double>>(V);
  pressure = std::make_shared<fem::Function<double>>(Q);
  _u_old = std::make_shared<fem::Function<double>>(V);
  _p_old = std::make_shared<fem::Function<double>>(Q);
  u_before = std::make_shared<fem::Function<double>>(V);
  p_before = std::make_shared<fem::Function<double>>(Q);
  interpolate(*pressure, {_scene.flow->initial_pressure}, 0.0);
  std::span<double> x = _x->x()->mutable_array();
  for (std::size_t i = 0; i < _Q_to_X.size(); ++i)
    x[_Q_to_X[i]] = pressure->x()->array()[i];
}

/// Body force, tractions, source, boundary pressures and gravity, in that
/// order, with the Dirichlet values at t (lifted with the history term).
void MonolithicStep::make_loads(const Domain& domain, const CompiledForms& forms, const Constants& constants)
{
  auto D = std::make_shared<fem::FunctionSpace>(fem::create_functionspace(forms.data_space, "source", domain.mesh));
  auto traction = std::make_shared<fem::Function<double>>(V);
  auto source = std::make_shared<fem::Function<double>>(D), p_boundary = std::make_shared<fem::Function<double>>(D);
  const Coefficients data = {{"traction", traction}, {"source", source}, {"p_boundary", p_boundary}};
  auto make = [&](const ufcx_form* f, const mesh::MeshTags<std::int32_t>* marker = nullptr)
  { return make_form(f, {_X}, data, constants, marker); };
  _loads = std::make_unique<Loads>(_X->dofmap()->index_map, _X->dofmap()->index_map_bs(),
                                   [this](la::Vector<double>& b, double t)
                                   {
                                     add_wells(_wells, t, b.mutable_array());
                                     update(_bc_values, t);
                                     update(_fluxes, t);
                                   });
  for (const auto& bc : _bc_values)
    _loads->depends_on_time(bc.value->depends_on_time());
  for (const FluxBoundary& f : _fluxes.boundaries)
    _loads->depends_on_time((f.rate ? f.rate : f.flux)->depends_on_time());
  _wells = well_sources(_scene, domain, *Q, _Q_to_X);
  _loads->depends_on_time(depends_on_time(_wells));
  add_body_force(*_loads, _scene, domain, forms,
                 {forms.L_monolithic_body_force, forms.L_monolithic_body_force_cells, {_X}, V}, constants);
  for (const auto& [name, b] : _scene.boundaries)
    if (!b.traction.empty()) // a traction boundary, or a loaded contact boundary
      _loads->add_boundary(
          domain, name, [&](const mesh::MeshTags<std::int32_t>* m) { return make(forms.L_monolithic_traction, m); },
          traction, b.traction);
  if (_scene.flow->source)
    _loads->add(make(forms.L_monolithic_source), source, {*_scene.flow->source});
  for (const auto& [name, b] : _scene.boundaries)
    if (b.flow == BoundarySpec::Flow::pressure)
      _loads->add_boundary(
          domain, name, [&](const mesh::MeshTags<std::int32_t>* m) { return make(forms.L_monolithic_pressure, m); },
          p_boundary, {b.pressure});
  if (_scene.flow->gravity)
    _loads->add(make(forms.L_monolithic_gravity));
  for (const auto& [name, f] : _scene.faults)
    if (f.pressure) // the fault's fluid pressure on both its faces, and its flow condition
    {
      auto pressure = std::make_shared<fem::Function<double>>(D);
      const Coefficients face = {{"p_boundary", pressure}};
      auto add = [&](const ufcx_form* form)
      {
        _loads->add_on_facets(
            domain.fault_faces(name), [&](const mesh::MeshTags<std::int32_t>* m)
            { return make_form(form, {_X}, face, constants, m); }, pressure, {*f.pressure});
      };
      add(forms.L_monolithic_face_pressure);
      if (f.flow == FaultFlow::pressure)
        add(forms.L_monolithic_pressure);
    }
}

/// Contact: the bounds sit on DOFs of the displacement block (contact.h).
void MonolithicStep::attach_contact(const Domain& domain, const CompiledForms& forms)
{
  ContactSet set = locate_contact(_scene, domain, forms, V);
  set.shear_modulus = pair_shear_moduli(set, *V, *_problem.materials.coefficients.at("G"));
  _moments = moments_of(set);
  const std::int32_t owned_X = owned_size(*_X);
  const std::int32_t owned_V = owned_size(*V);
  std::vector<std::int32_t> displacement;
  for (std::int32_t i = 0; i < owned_V; ++i)
    displacement.push_back(_V_to_X[i]);
  for (std::int32_t dof : displacement)
    if (dof >= owned_X)
      throw std::runtime_error("monolithic contact: a displacement DOF owned in V is not owned in the mixed space");
  make_contact_fields(set, contact_pressure, contact_active, contact_boundary);
  // The pressure rows are the rock's mass balances.
  std::vector<std::int32_t> balances;
  for (std::int32_t dof : _Q_to_X)
    if (dof < owned_X)
      balances.push_back(dof);
  _system->use_contact(std::move(set), std::move(displacement), wrap(*_b).vec(), std::move(balances));
}

MonolithicStep::~MonolithicStep() = default;

std::vector<Field> MonolithicStep::fields() const
{
  const auto& map = *_X->dofmap()->index_map; // block size 1
  const MPI_Comm comm = map.comm();
  const std::vector<PetscInt> z = owned_global_dofs(map, _Z_to_X), p = owned_global_dofs(map, _Q_to_X),
                              u = owned_global_dofs(map, _V_to_X);
  Field flow{"flow", {}};
  std::merge(z.begin(), z.end(), p.begin(), p.end(), std::back_inserter(flow.dofs));
  flow.fields = {part_of(flow, "flux", z, comm), part_of(flow, "pressure", p, comm)};

  // The displacement block, node by node (dolfinx numbers the components of
  // a node of the mixed space together), with the rigid-body modes laid out
  // in its numbering: the position of each owned DOF of V among u.
  const int d = V->dofmap()->index_map_bs();
  const std::int32_t owned_V = owned_size(*V);
  const std::int64_t first = map.local_range()[0];
  std::vector<std::int32_t> position(owned_V);
  for (std::int32_t i = 0; i < owned_V; ++i)
    position[i] = static_cast<std::int32_t>(std::lower_bound(u.begin(), u.end(), first + _V_to_X[i]) - u.begin());
  Field mechanics{"mechanics", u, d};
  mechanics.near_nullspace = own(rigid_body_modes(*V, position));
  // Flow first: the fixed-stress sweep solves the flow, then the mechanics
  // with the new pressure.
  return {std::move(flow), std::move(mechanics)};
}

void MonolithicStep::assemble_rhs(double t)
{
  common::Timer assembly("assembly");
  // Backward Euler from the state at the previous time, or from BDF2's
  // history values (time_scheme.h).
  const std::vector<double> u_old = history_value(_derivative, u->x()->array(), u_before->x()->array());
  const std::vector<double> p_old = history_value(_derivative, pressure->x()->array(), p_before->x()->array());
  std::copy(u_old.begin(), u_old.end(), _u_old->x()->mutable_array().begin());
  std::copy(p_old.begin(), p_old.end(), _p_old->x()->mutable_array().begin());
  const la::Vector<double>& loads = _loads->at(t);
  std::copy(loads.array().begin(), loads.array().end(), _b->mutable_array().begin());
  add_vector(*_b, *_L_history);
  finish_rhs(*_b, _a, _bcs);
  assembly_time += assembly.stop();
}

void MonolithicStep::set_displacement(std::span<const double> values, double t)
{
  std::copy(values.begin(), values.end(), u->x()->mutable_array().begin());
  std::span<double> x = _x->x()->mutable_array();
  std::span<const double> p = pressure->x()->array();
  for (std::size_t i = 0; i < _V_to_X.size(); ++i)
    x[_V_to_X[i]] = values[i];
  for (std::size_t i = 0; i < _Q_to_X.size(); ++i)
    x[_Q_to_X[i]] = p[i];
  // The residual of this state at t is what contact_state() reads.
  assemble_rhs(t);
}

void MonolithicStep::solve(double t, const TimeDerivative& d)
{
  _derivative = d;
  assemble_rhs(t);
  if (*_conduits)
  {
    _conduits->set_time_derivative(*_system, d);
    solve_with_conduits(t);
  }
  else
    recorded_solve(true, [&] { solve_system(); });
}

SolveFields MonolithicStep::solve_fields() const
{
  const bool conduits = bool(*_conduits);
  const std::span<const double> p_f = conduits ? std::span<const double>(_conduits->pressure()) : std::span<const double>();
  return {{pressure->x()->array(), owned_size(*Q), true},
          {u->x()->array(), owned_size(*V), true},
          {p_f, static_cast<std::int32_t>(p_f.size()), conduits},
          V->mesh()->comm()};
}

void MonolithicStep::solve_system()
{
  la::petsc::Vector x = wrap(*_x->x()), b = wrap(*_b);
  _system->solve(b.vec(), x.vec());
  _x->x()->scatter_fwd();
  extract(*_x, _V_to_X, *u);
  extract(*_x, _Q_to_X, *pressure);
}

void MonolithicStep::solve_with_conduits(double t)
{
  const int most = _scene.coupling->max_iterations;
  for (int i = 1;; ++i)
  {
    bool settled = false;
    // Newton's term of the transmissibilities only speeds the iteration up:
    // where the contact solve fails with it, the same iterate is solved
    // again without it (fault_reactivation's opening at dt = 6 h, whose
    // first such solve ended in DIVERGED_LINE_SEARCH).
    const std::vector<double> iterate = _conduits->newton() ? values(unknowns()) : std::vector<double>{};
    try
    {
      recorded_solve(i == 1,
                     [&]
                     {
                       _conduits->load(*_system, *_x->x(), t);
                       solve_system();
                       _fault_traction = fault_normal_stress();
                       settled = _conduits->update(*_system, *u->x(), _fault_traction);
                     });
    }
    catch (const SolverError&)
    {
      if (iterate.empty() or i == most)
        throw;
      set_unknowns(iterate);
      _conduits->drop_newton(*_system);
      continue;
    }
    if (settled)
      return;
    if (i == most)
      throw SolverError("monolithic: the conduit faults' apertures still move after " + std::to_string(most)
                        + " iterations (coupling.max_iterations): " + _conduits->last_change());
  }
}

std::vector<double> MonolithicStep::fault_normal_stress()
{
  if (!_conduits->has_closure())
    return {};
  return _conduits->normal_stress(contact_state());
}

void MonolithicStep::time_step_changed()
{
  _system->reassemble();
  if (*_conduits)
    _conduits->append(*_system);
}

std::span<const double> MonolithicStep::unknowns() const
{
  if (!*_conduits)
    return _x->x()->array();
  _unknowns.assign(_x->x()->array().begin(), _x->x()->array().end());
  _unknowns.insert(_unknowns.end(), _conduits->pressure().begin(), _conduits->pressure().end());
  return _unknowns;
}

void MonolithicStep::set_unknowns(std::span<const double> x)
{
  const std::size_t n = _x->x()->array().size();
  if (x.size() > n)
    std::copy(x.begin() + n, x.end(), _conduits->pressure().begin());
  std::copy_n(x.begin(), n, _x->x()->mutable_array().begin());
  extract(*_x, _V_to_X, *u);
  extract(*_x, _Q_to_X, *pressure);
}

void MonolithicStep::flux(fem::Function<double>& out) const
{
  fem::Function<double> z(_Z);
  extract(*_x, _Z_to_X, z);
  out.interpolate(z);
}

ActiveSet MonolithicStep::active_contact_set()
{
  if (!_system->has_contact())
    return {};
  la::petsc::Vector x = wrap(*_x->x()), b = wrap(*_b);
  return _system->contact().active_set(_system->whole(x.vec(), b.vec()).first);
}

ContactState MonolithicStep::contact_state()
{
  if (!_system->has_contact())
    return {};
  la::petsc::Vector x = wrap(*_x->x()), b = wrap(*_b);
  const auto [X, B] = _system->whole(x.vec(), b.vec());
  return _system->contact().state(X, B, *contact_pressure, *contact_active);
}

std::vector<SolveRecord> MonolithicStep::equilibrate()
{
  MechanicsStep step(_problem, V, pressure);
  if (*_conduits) // the conduit faults' pressure on their faces too
    step.load_fault_pressure(_conduits->aperture(), _conduits->pressure());
  const std::vector<SolveRecord> records = step.equilibrate();
  set_displacement(step.u->x()->array(), 0.0);
  _fault_traction = step.fault_traction();
  return records;
}

StepState MonolithicStep::state() const
{
  return {values(unknowns()), values(pressure->x()->array()), values(u->x()->array())};
}

void MonolithicStep::keep_history(const StepState& start)
{
  assign(*p_before, start.p);
  assign(*u_before, start.u);
}

History MonolithicStep::history() const
{
  if (_scene.time_scheme != TimeScheme::bdf2)
    return {};
  return {{"pressure_before", p_before.get()}, {"displacement_before", u_before.get()}};
}

bool MonolithicStep::same_contact_set(const ActiveSet& before)
{
  return same_active_set(active_contact_set(), before, V->mesh()->comm());
}

void MonolithicStep::begin_step()
{
  la::petsc::Vector x = wrap(*_x->x());
  if (*_conduits)
    _conduits->begin_step(*_system, *u->x(), _fault_traction);
  _system->begin_step(x.vec());
}

void MonolithicStep::accept(double t)
{
  la::petsc::Vector x = wrap(*_x->x());
  _system->accept_step(x.vec());
  if (!_moments.names.empty()) // no fault: nothing to record, no contact state computed
    record_moments(_moments, t, contact_state());
  if (*_conduits)
    _conduits->accept(_x->x()->array(), t);
}

std::string MonolithicStep::unbalanced(double t) const
{
  if (!*_conduits)
    return {};
  const std::span<const double> x = _x->x()->array();
  return _conduits->unbalanced(x, t, largest_entry(x, _Z_to_X, _Z->mesh()->comm()));
}

std::vector<double> MonolithicStep::fault_flow(double t) const
{
  return *_conduits ? _conduits->cell_values(_x->x()->array(), t) : std::vector<double>{};
}

std::vector<std::pair<std::string, FaultVolumes>> MonolithicStep::fault_volumes() const
{
  return *_conduits ? _conduits->volumes() : std::vector<std::pair<std::string, FaultVolumes>>{};
}

std::vector<IntersectionRate> MonolithicStep::fault_intersections() const
{
  return *_conduits ? _conduits->intersection_rates() : std::vector<IntersectionRate>{};
}

std::map<std::string, std::vector<double>> MonolithicStep::arrays() const
{
  std::map<std::string, std::vector<double>> arrays;
  keep_moments(_moments, arrays);
  if (*_conduits)
    _conduits->keep(arrays);
  if (!_fault_traction.empty())
    arrays["fault_traction"] = _fault_traction;
  if (_system->has_contact() and cohesive(_system->contact().set()))
    arrays["broken_bonds"] = _system->contact().broken_bonds();
  return arrays;
}

void MonolithicStep::restore_arrays(const std::map<std::string, std::vector<double>>& arrays)
{
  restore_moments(_moments, arrays);
  if (const auto found = arrays.find("broken_bonds"); found != arrays.end())
    _system->contact().restore_bonds(found->second);
  if (*_conduits)
    _conduits->restore(arrays);
  if (const auto found = arrays.find("fault_traction"); found != arrays.end())
    _fault_traction = found->second;
}

} // namespace biotcontact
