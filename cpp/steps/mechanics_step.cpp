#include "steps/mechanics_step.h"

#include "assembly/boundary_conditions.h"

#include <dolfinx/common/Timer.h>
#include <dolfinx/fem/assembler.h>
#include <dolfinx/fem/utils.h>
#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

namespace biotcontact
{
using namespace dolfinx;

MechanicsStep::MechanicsStep(const Problem& problem, std::shared_ptr<const fem::FunctionSpace> V,
                             std::shared_ptr<const fem::Function<double>> pressure)
    : _scene(problem.scene), _V(V)
{
  const Scene& scene = problem.scene;
  const Domain& domain = problem.domain;
  const CompiledForms& forms = problem.forms;
  const Materials& materials = problem.materials;
  const Constants& constants = problem.constants;
  u = std::make_shared<fem::Function<double>>(_V);
  for (const auto& [name, f] : scene.faults)
    _closure = _closure or f.closure.has_value();
  // Dirichlet conditions, one per prescribed component of each boundary.
  _bcs = displacement_bcs(scene, domain, _V, _bc_values);
  _a = make_form(forms.a_elastic, {_V, _V}, materials.coefficients, constants);
  make_loads(domain, forms, constants);
  if (!pressure and scene.mechanics->pore_pressure)
  {
    // One-way coupling: the pressure is given, taken in P0 at the cell
    // midpoints as the flow's would be, and loads the skeleton through the
    // same operator as the flow's.
    given_pressure = std::make_shared<fem::Function<double>>(std::make_shared<fem::FunctionSpace>(
        fem::create_functionspace(forms.material_space, "G", domain.mesh)));
    interpolate(*given_pressure, {*scene.mechanics->pore_pressure}, 0.0);
    pressure = given_pressure;
  }
  if (pressure)
  {
    // The pressure load (alpha p, div v) is applied as an operator on p.
    _pressure = pressure;
    _pressure_load.emplace(assemble_operator(
        *make_form(forms.a_pressure_load, {_V, pressure->function_space()}, materials.coefficients, constants,
                   pore_pressure_faces(scene, domain).get()),
        _bcs));
  }

  // a(u, v) does not change during a run: assembled once; with Dirichlet
  // rows made identity rows it is SPD.
  _system = std::make_unique<System>(domain.mesh->comm(), _a, _bcs, SystemLayout{"mechanics_", Structure::spd},
                                     scene.solver.mechanics);
  if (_system->method() == Method::iterative)
  {
    MatNullSpace modes = rigid_body_modes(*_V);
    _system->set_near_nullspace(modes);
    check_petsc(MatNullSpaceDestroy(&modes), "the mechanics: MatNullSpaceDestroy of the rigid-body modes");
  }
  _b = std::make_unique<la::Vector<double>>(_V->dofmap()->index_map, _V->dofmap()->index_map_bs());
  if (scene.has_contact())
    attach_contact(domain, forms, materials);
}

/// Body force and tractions (also on a loaded contact boundary), in that
/// order, lifted and with their Dirichlet values at t.
void MechanicsStep::make_loads(const Domain& domain, const CompiledForms& forms, const Constants& constants)
{
  auto traction = std::make_shared<fem::Function<double>>(_V);
  const Coefficients data = {{"traction", traction}};
  _loads = std::make_unique<Loads>(_V->dofmap()->index_map, _V->dofmap()->index_map_bs(),
                                   [this](la::Vector<double>& b, double t)
                                   {
                                     update(_bc_values, t);
                                     finish_rhs(b, _a, _bcs);
                                   });
  for (const auto& bc : _bc_values)
    _loads->depends_on_time(bc.value->depends_on_time());
  add_body_force(*_loads, _scene, domain, forms, {forms.L_body_force, forms.L_body_force_cells, {_V}, _V}, constants);
  for (const auto& [name, b] : _scene.boundaries)
    if (!b.traction.empty())
      _loads->add_boundary(
          domain, name, [&](const mesh::MeshTags<std::int32_t>* marker)
          { return make_form(forms.L_traction, {_V}, data, constants, marker); }, traction, b.traction);
  add_fault_pressures(domain, forms, constants);
}

/// A fault's fluid pressure pushing on both its faces (fault.NAME.pressure).
void MechanicsStep::add_fault_pressures(const Domain& domain, const CompiledForms& forms, const Constants& constants)
{
  for (const auto& [name, f] : _scene.faults)
  {
    if (!f.pressure)
      continue;
    auto D = std::make_shared<fem::FunctionSpace>(fem::create_functionspace(forms.data_space, "source", domain.mesh));
    auto pressure = std::make_shared<fem::Function<double>>(D);
    const Coefficients data = {{"p_boundary", pressure}};
    _loads->add_on_facets(
        domain.fault_faces(name), [&](const mesh::MeshTags<std::int32_t>* marker)
        { return make_form(forms.L_face_pressure, {_V}, data, constants, marker); }, pressure, {*f.pressure});
  }
}

/// Contact: a bound for each constraint u.nu_F <= g_a of Gamma_3 (contact.h).
void MechanicsStep::attach_contact(const Domain& domain, const CompiledForms& forms, const Materials& materials)
{
  ContactSet set = locate_contact(_scene, domain, forms, _V);
  set.shear_modulus = pair_shear_moduli(set, *_V, *materials.coefficients.at("G"));
  _moments = moments_of(set);
  std::vector<std::int32_t> owned(owned_size(*_V));
  std::iota(owned.begin(), owned.end(), 0);
  make_contact_fields(set, contact_pressure, contact_active, contact_boundary);
  // The mechanics alone over one step solves the contact once.
  const bool once = !_scene.flow and !_scene.adaptive and _scene.num_steps() == 1;
  _system->use_contact(std::move(set), std::move(owned), wrap(*_b).vec(), {}, once);
}

MechanicsStep::~MechanicsStep() = default;

void MechanicsStep::assemble_rhs(double t)
{
  // The loads change with t only; the pressure load changes every
  // iteration: one product with its operator, whose Dirichlet rows are zero.
  const la::Vector<double>& loads = _loads->at(t);
  std::copy(loads.array().begin(), loads.array().end(), _b->mutable_array().begin());
  if (given_pressure)
    interpolate(*given_pressure, {*_scene.mechanics->pore_pressure}, t);
  if (_pressure_load)
    multiply_add(_pressure_load->mat(), *_pressure->x(), *_b);
  if (_fault_load.aperture)
    _fault_load.aperture->add_load(*_fault_load.pressure, _bcs, *_b);
}

void MechanicsStep::solve(double t)
{
  common::Timer assembly("assembly");
  assemble_rhs(t);
  assembly_time += assembly.stop();

  la::petsc::Vector x = wrap(*u->x());
  _system->solve(wrap(*_b).vec(), x.vec());
  u->x()->scatter_fwd();
  if (_closure and _fault_load.aperture)
    _fault_traction = _fault_load.aperture->cell_means(pair_tractions(contact_state()));
}

ContactState MechanicsStep::contact_state()
{
  if (!_system->has_contact())
    return {};
  return _system->contact().state(wrap(*u->x()).vec(), wrap(*_b).vec(), *contact_pressure, *contact_active);
}

ActiveSet MechanicsStep::active_contact_set()
{
  return _system->has_contact() ? _system->contact().active_set(wrap(*u->x()).vec()) : ActiveSet{};
}

void MechanicsStep::pin_contact(std::vector<std::int8_t> pins)
{
  if (_system->has_contact())
    _system->contact().pin(std::move(pins));
}

std::vector<std::int8_t> MechanicsStep::consistent_pins()
{
  if (!_system->has_contact())
    return {};
  return _system->contact().consistent_pins(wrap(*u->x()).vec(), wrap(*_b).vec());
}

bool MechanicsStep::same_contact_set(const ActiveSet& before)
{
  return same_active_set(active_contact_set(), before, _V->mesh()->comm());
}

void MechanicsStep::begin_step()
{
  la::petsc::Vector x = wrap(*u->x());
  _system->begin_step(x.vec());
}

void MechanicsStep::accept(double t)
{
  la::petsc::Vector x = wrap(*u->x());
  _system->accept_step(x.vec());
  if (!_moments.names.empty()) // no fault: nothing to record, no contact state computed
    record_moments(_moments, t, contact_state());
}

std::map<std::string, std::vector<double>> MechanicsStep::arrays() const
{
  std::map<std::string, std::vector<double>> arrays;
  keep_moments(_moments, arrays);
  if (!_fault_traction.empty())
    arrays["fault_traction"] = _fault_traction;
  if (_system->has_contact() and cohesive(_system->contact().set()))
    arrays["broken_bonds"] = _system->contact().broken_bonds();
  return arrays;
}

void MechanicsStep::restore_arrays(const std::map<std::string, std::vector<double>>& arrays)
{
  restore_moments(_moments, arrays);
  if (const auto found = arrays.find("broken_bonds"); found != arrays.end())
    _system->contact().restore_bonds(found->second);
  if (const auto found = arrays.find("fault_traction"); found != arrays.end())
    _fault_traction = found->second;
}

} // namespace biotcontact
