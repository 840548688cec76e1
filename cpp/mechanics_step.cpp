#include "mechanics_step.h"

#include <dolfinx/common/Timer.h>
#include <dolfinx/fem/assembler.h>
#include <dolfinx/fem/utils.h>
#include <algorithm>
#include <cmath>
#include <limits>

namespace biotcontact
{
using namespace dolfinx;

MechanicsStep::MechanicsStep(const Scene& scene, const Domain& domain, const CompiledForms& forms,
                             const Constants& constants, std::shared_ptr<const fem::FunctionSpace> V,
                             std::shared_ptr<const fem::Function<double>> pressure)
    : _scene(scene), _V(V)
{
  const auto& mesh = domain.mesh;
  const int d = domain.dim();
  const int fdim = d - 1;
  u = std::make_shared<fem::Function<double>>(_V);

  _body_force = std::make_shared<fem::Function<double>>(_V);
  _traction = std::make_shared<fem::Function<double>>(_V);
  Coefficients coefficients = {{"body_force", _body_force}, {"traction", _traction}};
  if (pressure)
    coefficients["p"] = pressure;

  auto make = [&](const ufcx_form* f, std::vector<std::shared_ptr<const fem::FunctionSpace>> spaces,
                  const mesh::MeshTags<std::int32_t>* marker = nullptr)
  { return make_form(f, spaces, coefficients, constants, marker); };

  // Dirichlet conditions, one per prescribed component of each boundary.
  std::vector<std::int32_t> contact_facets;
  for (const auto& [name, b] : scene.boundaries)
  {
    const std::vector<std::int32_t>& facets = domain.boundaries.at(name);
    for (int i = 0; i < d; ++i)
    {
      if (!b.displacement[i])
        continue;
      auto Vi = _V->sub({i});
      auto collapsed = std::make_shared<fem::FunctionSpace>(Vi->collapse().first);
      auto g = std::make_shared<fem::Function<double>>(collapsed);
      auto dofs = fem::locate_dofs_topological({*Vi, *collapsed}, fdim, facets);
      _bcs.push_back(std::make_shared<fem::DirichletBC<double>>(g, std::move(dofs), Vi));
      _bc_values.push_back({&*b.displacement[i], g});
    }
    if (b.mechanics == BoundarySpec::Mechanics::traction)
    {
      _markers.push_back(domain.marker(name));
      _L_traction.emplace_back(&b.traction, make(forms.L_traction, {_V}, _markers.back().get()));
      for (const Expression& e : b.traction)
        _loads_depend_on_time = _loads_depend_on_time or e.depends_on_time();
    }
    if (b.contact)
      contact_facets.insert(contact_facets.end(), facets.begin(), facets.end());
  }
  for (auto& bc : _bc_values)
    _loads_depend_on_time = _loads_depend_on_time or bc.value->depends_on_time();

  _a = make(forms.a_elastic, {_V, _V});
  if (pressure)
    _L_pressure = make(forms.L_pressure_load, {_V});
  if (scene.mechanics->body_force)
  {
    _L_body = make(forms.L_body_force, {_V});
    for (const Expression& e : *scene.mechanics->body_force)
      _loads_depend_on_time = _loads_depend_on_time or e.depends_on_time();
  }

  // a(u, v) does not change during a run: assembled once.
  common::Timer timer("assembly");
  _A.emplace(assemble_matrix(*_a, _bcs));
  assembly_time += timer.stop();

  const auto& map = _V->dofmap()->index_map;
  const int bs = _V->dofmap()->index_map_bs();
  _b = std::make_unique<la::Vector<double>>(map, bs);
  _b_loads = std::make_unique<la::Vector<double>>(map, bs);

  if (contact_facets.empty())
  {
    _solver = std::make_unique<LinearSolver>(mesh->comm(), "mechanics_", _A->mat());
    return;
  }

  // ---- Contact: bounds on the normal DOF of every node of Gamma_3 --------
  std::sort(contact_facets.begin(), contact_facets.end());
  contact_facets.erase(std::unique(contact_facets.begin(), contact_facets.end()), contact_facets.end());
  Contact c;
  const auto& first = *std::find_if(scene.boundaries.begin(), scene.boundaries.end(),
                                    [](const auto& nb) { return nb.second.contact.has_value(); });
  c.axis = first.second.contact->axis;
  c.sign = first.second.contact->sign;
  for (const auto& [name, b] : scene.boundaries)
    if (b.contact and (b.contact->axis != c.axis or b.contact->sign != c.sign))
      throw SceneError(scene.file + ": boundary." + name
                       + ".contact.normal: all contact boundaries must share one foundation normal");

  // Lumped boundary measure of each node (to turn forces into pressures).
  auto contact_marker = std::make_shared<mesh::MeshTags<std::int32_t>>(
      mesh, fdim, std::vector<std::int32_t>(contact_facets),
      std::vector<std::int32_t>(contact_facets.size(), 1));
  _markers.push_back(contact_marker);
  la::Vector<double> lumped(map, bs);
  add_vector(lumped, *make(forms.L_lumped_boundary, {_V}, contact_marker.get()));
  lumped.scatter_rev(std::plus<double>());

  auto Vc = std::make_shared<fem::FunctionSpace>(_V->sub({c.axis})->collapse().first);
  contact_pressure = std::make_shared<fem::Function<double>>(Vc);
  contact_active = std::make_shared<fem::Function<double>>(Vc);
  const std::vector<double> coords = _V->tabulate_dof_coordinates(false);
  const std::int32_t owned = bs * map->size_local();
  auto [dofs, collapsed] = fem::locate_dofs_topological({*_V->sub({c.axis}), *Vc}, fdim, contact_facets);
  for (const auto& [name, b] : scene.boundaries)
  {
    if (!b.contact)
      continue;
    auto [bdofs, _] = fem::locate_dofs_topological({*_V->sub({c.axis}), *Vc}, fdim,
                                                   domain.boundaries.at(name));
    (void)_;
    for (std::size_t k = 0; k < dofs.size(); ++k)
    {
      if (dofs[k] >= owned or !std::binary_search(bdofs.begin(), bdofs.end(), dofs[k])
          or std::find(c.dofs.begin(), c.dofs.end(), dofs[k]) != c.dofs.end())
        continue;
      const double* x = &coords[3 * (dofs[k] / bs)];
      const double g = b.contact->gap(x, 0.0);
      if (!(g >= 0) or !std::isfinite(g))
        throw SceneError(scene.file + ": boundary." + name + ".contact.gap: must be >= 0, got "
                         + std::to_string(g) + " at (" + std::to_string(x[0]) + ", "
                         + std::to_string(x[1]) + ")");
      c.dofs.push_back(dofs[k]);
      c.gap.push_back(g);
      c.lumped.push_back(lumped.array()[dofs[k]]);
      c.collapsed.push_back(collapsed[k]);
    }
  }

  la::petsc::Vector b = wrap(*_b);
  VecDuplicate(b.vec(), &c.x);
  VecDuplicate(b.vec(), &c.residual);
  VecDuplicate(b.vec(), &c.lower);
  VecDuplicate(b.vec(), &c.upper);
  VecSet(c.lower, PETSC_NINFINITY);
  VecSet(c.upper, PETSC_INFINITY);
  VecDuplicate(b.vec(), &c.b_scaled);

  set_default_option("mechanics_ksp_type", "preonly");
  set_default_option("mechanics_pc_type", "lu");
  set_default_option("mechanics_pc_factor_mat_solver_type", "mumps");
  set_default_option("mechanics_snes_rtol", "1e-10");
  set_default_option("mechanics_snes_stol", "1e-12");
  set_default_option("mechanics_snes_max_it", "100");
  // F is linear and A is its exact Jacobian: the full semismooth Newton step
  // is exact on the current active set, and a backtracking search only
  // fails once the residual is at round-off.
  set_default_option("mechanics_snes_linesearch_type", "basic");
  SNESCreate(mesh->comm(), &c.snes);
  SNESSetOptionsPrefix(c.snes, "mechanics_");
  SNESSetType(c.snes, SNESVINEWTONRSLS);
  SNESSetFunction(c.snes, c.residual, &MechanicsStep::residual, this);
  SNESSetJacobian(c.snes, _A->mat(), _A->mat(), &MechanicsStep::jacobian, this);
  SNESVISetVariableBounds(c.snes, c.lower, c.upper);
  // At least one Newton step per solve: a step is an exact solve on the
  // active set, so the result never lags behind the load (a residual
  // already below the tolerance would otherwise leave u as it was).
  SNESSetForceIteration(c.snes, PETSC_TRUE);
  SNESSetFromOptions(c.snes);
  _contact = std::move(c);
}

MechanicsStep::~MechanicsStep()
{
  if (_contact)
  {
    SNESDestroy(&_contact->snes);
    VecDestroy(&_contact->x);
    VecDestroy(&_contact->residual);
    VecDestroy(&_contact->lower);
    VecDestroy(&_contact->upper);
    VecDestroy(&_contact->b_scaled);
  }
}

// F(x) = A x - b/s: the gradient of the (quadratic) energy in units of s.
PetscErrorCode MechanicsStep::residual(SNES, Vec x, Vec F, void* context)
{
  auto* self = static_cast<MechanicsStep*>(context);
  MatMult(self->_A->mat(), x, F);
  VecAXPY(F, -1.0, self->_contact->b_scaled);
  return 0;
}

// The Jacobian is the constant matrix A, assembled once.
PetscErrorCode MechanicsStep::jacobian(SNES, Vec, Mat, Mat, void*) { return 0; }

void MechanicsStep::assemble_rhs(double t)
{
  // Loads that only change with t are assembled once per time (once per run
  // when they are constant); the pressure load changes every iteration.
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
    for (auto& bc : _bc_values)
      interpolate(*bc.g, {*bc.value}, t);
    _loads_time = t;
    _loads_assembled = true;
  }
  std::copy(_b_loads->array().begin(), _b_loads->array().end(), _b->mutable_array().begin());
  if (_L_pressure)
    add_vector(*_b, *_L_pressure);
  finish_rhs(*_b, _a, _bcs);
}

void MechanicsStep::solve(double t)
{
  common::Timer assembly("assembly");
  assemble_rhs(t);
  assembly_time += assembly.stop();

  common::Timer timer("mechanics solve");
  la::petsc::Vector x = wrap(*u->x());
  if (!_contact)
    linear_iterations += _solver->solve(x.vec(), wrap(*_b).vec());
  else
  {
    // SNES works on its own vector (the callbacks evaluate trial points);
    // the previous u is the initial guess.
    Contact& c = *_contact;
    // SNESVI decides "on the bound" with an absolute tolerance (1e-8), so it
    // works on u / s with s the displacement scale (largest gap or |u|):
    // the residual A (u/s) - b/s has the same Jacobian A.
    double local = 0;
    for (double g : c.gap)
      local = std::max(local, g);
    for (double v : u->x()->array())
      local = std::max(local, std::abs(v));
    MPI_Allreduce(&local, &c.scale, 1, MPI_DOUBLE, MPI_MAX, _V->mesh()->comm());
    if (!(c.scale > 0))
      c.scale = 1.0;
    {
      PetscScalar *lo, *up;
      VecGetArray(c.lower, &lo);
      VecGetArray(c.upper, &up);
      // u.nu_F <= g_a with nu_F = sign e_axis: u_axis <= g_a or u_axis >= -g_a.
      for (std::size_t k = 0; k < c.dofs.size(); ++k)
      {
        if (c.sign > 0)
          up[c.dofs[k]] = c.gap[k] / c.scale;
        else
          lo[c.dofs[k]] = -c.gap[k] / c.scale;
      }
      VecRestoreArray(c.lower, &lo);
      VecRestoreArray(c.upper, &up);
    }
    VecCopy(wrap(*_b).vec(), c.b_scaled);
    VecScale(c.b_scaled, 1.0 / c.scale);
    VecCopy(x.vec(), c.x);
    VecScale(c.x, 1.0 / c.scale);
    PetscBool atol_given = PETSC_FALSE;
    PetscOptionsHasName(nullptr, nullptr, "-mechanics_snes_atol", &atol_given);
    if (!atol_given)
    {
      // Absolute tolerance relative to the load: scale-free.
      PetscReal bnorm = 0;
      VecNorm(c.b_scaled, NORM_2, &bnorm);
      SNESSetTolerances(c.snes, std::max(1e-10 * bnorm, 1e-300), PETSC_DEFAULT, PETSC_DEFAULT,
                        PETSC_DEFAULT, PETSC_DEFAULT);
    }
    SNESSolve(c.snes, nullptr, c.x);
    SNESConvergedReason reason;
    SNESGetConvergedReason(c.snes, &reason);
    if (reason < 0)
      throw SolverError(std::string("the contact solver (SNES vinewtonrsls) did not converge: ")
                        + SNESConvergedReasons[reason]);
    PetscInt its = 0, lits = 0;
    SNESGetIterationNumber(c.snes, &its);
    SNESGetLinearSolveIterations(c.snes, &lits);
    newton_iterations += its;
    linear_iterations += lits;
    VecScale(c.x, c.scale);
    VecCopy(c.x, x.vec());
  }
  u->x()->scatter_fwd();
  solve_time += timer.stop();
  ++solves;
}

ContactState MechanicsStep::contact_state()
{
  ContactState s;
  if (!_contact)
    return s;
  Contact& c = *_contact;
  // Nodal contact force R = A u - b (the residual of the unconstrained
  // equations); the contact pressure is -R.nu_F / lumped measure.
  la::petsc::Vector x = wrap(*u->x());
  MatMult(_A->mat(), x.vec(), c.residual);
  VecAXPY(c.residual, -1.0, wrap(*_b).vec());
  const PetscScalar* R;
  VecGetArrayRead(c.residual, &R);
  std::span<const double> ux = u->x()->array();
  std::span<double> pc = contact_pressure->x()->mutable_array();
  std::span<double> active = contact_active->x()->mutable_array();
  std::fill(pc.begin(), pc.end(), 0.0);
  std::fill(active.begin(), active.end(), 0.0);

  // Displacement scale: the largest gap or displacement anywhere.
  double local = 0;
  for (double v : u->x()->array())
    local = std::max(local, std::abs(v));
  std::vector<double> pressure(c.dofs.size()), normal(c.dofs.size());
  for (std::size_t k = 0; k < c.dofs.size(); ++k)
  {
    normal[k] = c.sign * ux[c.dofs[k]];
    pressure[k] = -c.sign * R[c.dofs[k]] / c.lumped[k];
    local = std::max({local, std::abs(c.gap[k]), std::abs(normal[k])});
  }
  VecRestoreArrayRead(c.residual, &R);
  double global = 0;
  MPI_Allreduce(&local, &global, 1, MPI_DOUBLE, MPI_MAX, u->function_space()->mesh()->comm());
  s.gap_scale = global > 0 ? global : 1.0;

  // A node is active when it lies on the foundation to round-off.
  double pen = -std::numeric_limits<double>::infinity(), comp = 0;
  double pmax = -std::numeric_limits<double>::infinity(), pmin = std::numeric_limits<double>::infinity();
  int n_active = 0;
  for (std::size_t k = 0; k < c.dofs.size(); ++k)
  {
    const double distance = c.gap[k] - normal[k];
    const bool is_active = distance <= 1e-9 * s.gap_scale;
    n_active += is_active;
    pen = std::max(pen, -distance);
    comp = std::max(comp, std::abs(pressure[k] * distance));
    pmax = std::max(pmax, pressure[k]);
    pmin = std::min(pmin, pressure[k]);
    pc[c.collapsed[k]] = pressure[k];
    active[c.collapsed[k]] = is_active ? 1.0 : 0.0;
  }
  contact_pressure->x()->scatter_fwd();
  contact_active->x()->scatter_fwd();
  MPI_Comm comm = u->function_space()->mesh()->comm();
  const int n_local[2] = {n_active, static_cast<int>(c.dofs.size())};
  int n_global[2];
  MPI_Allreduce(n_local, n_global, 2, MPI_INT, MPI_SUM, comm);
  s.active_nodes = n_global[0];
  s.contact_nodes = n_global[1];
  double maxes[4] = {pen, comp, pmax, -pmin}, gmax[4];
  MPI_Allreduce(maxes, gmax, 4, MPI_DOUBLE, MPI_MAX, comm);
  s.max_penetration = gmax[0];
  s.max_complementarity = gmax[1];
  s.max_pressure = gmax[2];
  s.min_pressure = -gmax[3];
  return s;
}

} // namespace biotcontact
