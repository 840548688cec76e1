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

MechanicsStep::MechanicsStep(const Scene& scene, const Domain& domain, const CompiledForms& forms,
                             const Constants& constants, std::shared_ptr<const fem::FunctionSpace> V,
                             std::shared_ptr<const fem::Function<double>> pressure)
    : _scene(scene), _V(V)
{
  const auto& mesh = domain.mesh;
  u = std::make_shared<fem::Function<double>>(_V);

  _body_force = std::make_shared<fem::Function<double>>(_V);
  _traction = std::make_shared<fem::Function<double>>(_V);
  const Coefficients coefficients = {{"body_force", _body_force}, {"traction", _traction}};

  auto make = [&](const ufcx_form* f, std::vector<std::shared_ptr<const fem::FunctionSpace>> spaces,
                  const mesh::MeshTags<std::int32_t>* marker = nullptr)
  { return make_form(f, spaces, coefficients, constants, marker); };

  // Dirichlet conditions, one per prescribed component of each boundary.
  _bcs = displacement_bcs(scene, domain, _V, _bc_values);
  for (const auto& [name, b] : scene.boundaries)
  {
    if (!b.traction.empty()) // a traction boundary, or a loaded contact boundary
    {
      _markers.push_back(domain.marker(name));
      _L_traction.emplace_back(&b.traction, make(forms.L_traction, {_V}, _markers.back().get()));
      for (const Expression& e : b.traction)
        _loads_depend_on_time = _loads_depend_on_time or e.depends_on_time();
    }
  }
  for (auto& bc : _bc_values)
    _loads_depend_on_time = _loads_depend_on_time or bc.value->depends_on_time();

  _a = make(forms.a_elastic, {_V, _V});
  if (pressure)
  {
    // The pressure load (alpha p, div v) is applied as an operator on p.
    _pressure = pressure;
    _pressure_load.emplace(
        assemble_operator(*make(forms.a_pressure_load, {_V, pressure->function_space()}), _bcs));
  }
  if (scene.mechanics->body_force)
  {
    _L_body = make(forms.L_body_force, {_V});
    for (const Expression& e : *scene.mechanics->body_force)
      _loads_depend_on_time = _loads_depend_on_time or e.depends_on_time();
  }

  // a(u, v) does not change during a run: assembled once; with Dirichlet
  // rows made identity rows it is SPD.
  _system = std::make_unique<System>(mesh->comm(), "mechanics_", _a, _bcs, Structure::spd, scene.solver.mechanics);
  if (_system->method() == Method::iterative)
  {
    MatNullSpace modes = rigid_body_modes(*_V);
    _system->set_near_nullspace(modes);
    MatNullSpaceDestroy(&modes);
  }

  const auto& map = _V->dofmap()->index_map;
  const int bs = _V->dofmap()->index_map_bs();
  _b = std::make_unique<la::Vector<double>>(map, bs);
  _b_loads = std::make_unique<la::Vector<double>>(map, bs);
  if (!scene.has_contact())
    return;

  // ---- Contact: bounds on the normal DOF of every node of Gamma_3 --------
  ContactSet set = locate_contact(scene, domain, forms, _V);
  std::vector<std::int32_t> dofs = set.dofs;
  std::vector<std::int32_t> owned(bs * map->size_local());
  std::iota(owned.begin(), owned.end(), 0);
  contact_pressure = std::make_shared<fem::Function<double>>(set.output_space);
  contact_active = std::make_shared<fem::Function<double>>(set.output_space);
  contact_boundary = contact_boundary_flag(set);
  _system->use_contact(std::move(set), std::move(dofs), std::move(owned), wrap(*_b).vec());
}

MechanicsStep::~MechanicsStep() = default;

void MechanicsStep::assemble_rhs(double t)
{
  // Loads that only change with t are assembled, lifted and given their
  // Dirichlet values once per time (once per run when they are constant);
  // the pressure load changes every iteration: one product with its
  // operator, whose Dirichlet rows are zero.
  if (!_loads_assembled or (_loads_depend_on_time and t != _loads_time))
  {
    _b_loads->set(0.0);
    if (_L_body)
    {
      interpolate(*_body_force, *_scene.mechanics->body_force, t);
      add_vector(*_b_loads, *_L_body);
    }
    for (const auto& [traction, form] : _L_traction)
    {
      interpolate(*_traction, *traction, t);
      add_vector(*_b_loads, *form);
    }
    update(_bc_values, t);
    finish_rhs(*_b_loads, _a, _bcs);
    _loads_time = t;
    _loads_assembled = true;
  }
  std::copy(_b_loads->array().begin(), _b_loads->array().end(), _b->mutable_array().begin());
  if (_pressure_load)
    multiply_add(_pressure_load->mat(), *_pressure->x(), *_b);
}

void MechanicsStep::solve(double t)
{
  common::Timer assembly("assembly");
  assemble_rhs(t);
  assembly_time += assembly.stop();

  la::petsc::Vector x = wrap(*u->x());
  _system->solve(wrap(*_b).vec(), x.vec());
  u->x()->scatter_fwd();
}

ContactState MechanicsStep::contact_state()
{
  if (!_system->has_contact())
    return {};
  return _system->contact().state(wrap(*u->x()).vec(), wrap(*_b).vec(), *contact_pressure, *contact_active);
}

int MechanicsStep::active_contact_nodes()
{
  return _system->has_contact() ? _system->contact().active_nodes(wrap(*u->x()).vec()) : 0;
}

} // namespace biotcontact
