#include "contact/contact.h"

#include "assembly/linear_algebra.h"

#include <algorithm>
#include <cmath>
#include <dolfinx/fem/DirichletBC.h>
#include <dolfinx/fem/FunctionSpace.h>
#include <limits>
#include <optional>
#include <set>

namespace biotcontact
{
using namespace dolfinx;

std::shared_ptr<fem::Function<double>> contact_boundary_flag(const ContactSet& set)
{
  auto flag = std::make_shared<fem::Function<double>>(set.output_space);
  std::span<double> values = flag->x()->mutable_array();
  for (std::int32_t dof : set.output_dofs)
    values[dof] = 1.0;
  flag->x()->scatter_fwd();
  flag->name = "contact_boundary";
  return flag;
}

void make_contact_fields(const ContactSet& set, std::shared_ptr<fem::Function<double>>& pressure,
                         std::shared_ptr<fem::Function<double>>& active, std::shared_ptr<fem::Function<double>>& boundary)
{
  pressure = std::make_shared<fem::Function<double>>(set.output_space);
  active = std::make_shared<fem::Function<double>>(set.output_space);
  boundary = contact_boundary_flag(set);
}

ContactSet locate_contact(const Scene& scene, const Domain& domain, const CompiledForms& forms,
                          std::shared_ptr<const fem::FunctionSpace> V)
{
  const int fdim = domain.dim() - 1;
  ContactSet c;
  std::vector<std::int32_t> facets;
  bool first = true;
  for (const auto& [name, b] : scene.boundaries)
  {
    if (!b.contact)
      continue;
    if (first)
    {
      c.axis = b.contact->axis;
      c.sign = b.contact->sign;
      first = false;
    }
    else if (b.contact->axis != c.axis or b.contact->sign != c.sign)
      throw SceneError(scene.file + ": boundary." + name
                       + ".contact.normal: all contact boundaries must share one foundation normal");
    const auto& f = domain.boundaries.at(name);
    facets.insert(facets.end(), f.begin(), f.end());
  }
  std::sort(facets.begin(), facets.end());
  facets.erase(std::unique(facets.begin(), facets.end()), facets.end());

  // Lumped boundary measure of each node: the integral of its hat function.
  auto marker = std::make_shared<mesh::MeshTags<std::int32_t>>(
      domain.mesh, fdim, std::vector<std::int32_t>(facets), std::vector<std::int32_t>(facets.size(), 1));
  const auto& map = V->dofmap()->index_map;
  const int bs = V->dofmap()->index_map_bs();
  la::Vector<double> lumped(map, bs);
  const Constants ones = {
      {"ones", std::make_shared<const fem::Constant<double>>(std::vector<double>(domain.dim(), 1.0))}};
  add_vector(lumped, *make_form(forms.L_lumped_boundary, {V}, {}, ones, marker.get()));
  lumped.scatter_rev(std::plus<double>());

  auto Vi = V->sub({c.axis});
  c.output_space = std::make_shared<fem::FunctionSpace>(Vi->collapse().first);
  const std::vector<double> coords = V->tabulate_dof_coordinates(false);
  const std::int32_t owned = bs * map->size_local();
  std::set<std::int32_t> seen;
  std::string error; // the first bad gap on this rank
  for (const auto& [name, b] : scene.boundaries)
  {
    if (!b.contact)
      continue;
    auto [dofs, collapsed]
        = fem::locate_dofs_topological({*Vi, *c.output_space}, fdim, domain.boundaries.at(name));
    for (std::size_t k = 0; k < dofs.size(); ++k)
    {
      if (dofs[k] >= owned or !seen.insert(dofs[k]).second)
        continue;
      const double* x = &coords[3 * (dofs[k] / bs)];
      const double g = b.contact->gap(x, 0.0);
      if ((!(g >= 0) or !std::isfinite(g)) and error.empty())
        error = scene.file + ": boundary." + name + ".contact.gap: must be >= 0, got " + std::to_string(g)
                + " at (" + std::to_string(x[0]) + ", " + std::to_string(x[1]) + ")";
      c.dofs.push_back(dofs[k]);
      c.gap.push_back(g);
      c.lumped.push_back(lumped.array()[dofs[k]]);
      c.output_dofs.push_back(collapsed[k]);
    }
  }
  agree_on_error(error, domain.mesh->comm());
  return c;
}

namespace
{
/// Whether the VI is posed on the Schur complement: -<prefix>contact_condensed,
/// by default when the system is solved directly and C is small enough.
bool use_condensation(const std::string& prefix, Method method, PetscInt contact_dofs)
{
  PetscBool condensed = PETSC_FALSE, given = PETSC_FALSE;
  PetscOptionsGetBool(nullptr, prefix.c_str(), "-contact_condensed", &condensed, &given);
  if (given)
    return condensed;
  // Forming H takes m solves: cheap back-solves of a factorisation, but m
  // full Krylov solves with an iterative method.
  return method == Method::direct and contact_dofs <= ContactSolver::max_condensed_dofs;
}
} // namespace

ContactSolver::ContactSolver(MPI_Comm comm, const std::string& prefix, Mat A, Mat P, const std::vector<Field>& fields,
                             Structure structure, Method method, Vec layout, ContactSet set,
                             std::vector<std::int32_t> dofs, std::vector<std::int32_t> displacement_dofs)
    : _comm(comm), _A(A), _P(P), _fields(fields), _structure(structure), _prefix(prefix), _set(std::move(set)),
      _dofs(std::move(dofs)),
      _displacement_dofs(std::move(displacement_dofs))
{
  // MAT_SPD carries over to the inactive-set submatrices: Cholesky there.
  if (structure == Structure::spd)
    MatSetOption(A, MAT_SPD, PETSC_TRUE);
  VecDuplicate(layout, &_force);

  long local_dofs = static_cast<long>(_dofs.size()), contact_dofs = 0;
  MPI_Allreduce(&local_dofs, &contact_dofs, 1, MPI_LONG, MPI_SUM, comm);
  const bool condensed = use_condensation(prefix, method, contact_dofs);
  if (condensed)
    condense();
  else
    pose_on_full_system(layout);
  const std::string vi_prefix = condensed ? prefix + "contact_" : prefix;
  create_snes(vi_prefix);
  if (!condensed and method == Method::iterative)
  {
    _preconditioner = std::make_unique<InactiveSetPreconditioner>(_snes, P, fields, prefix);
    KSP ksp;
    SNESGetKSP(_snes, &ksp);
    KSPMonitorSet(ksp, &ContactSolver::stagnation, this, nullptr);
    set_tolerance(iterative_tolerance);
  }
  if (PetscErrorCode ierr = SNESSetFromOptions(_snes); ierr != 0)
    throw OptionsError("the PETSc options of " + system_name(prefix)
                       + " contact solver do not make a solver (PETSc error " + std::to_string(ierr) + ")");
  // Only the VI methods take bounds; any other would ignore the contact.
  // Asked of both prefixes, so that a type given for the path not taken
  // is not ignored silently either.
  for (const std::string& p : {prefix, prefix + "contact_"})
  {
    const std::string type = option(p, "-snes_type");
    if (!type.empty() and type != SNESVINEWTONRSLS and type != SNESVINEWTONSSLS)
      throw OptionsError("-" + p + "snes_type " + type
                         + ": the contact solver needs a bound-constrained method (vinewtonrsls or vinewtonssls)");
  }
}

/// The VI on the Schur complement H = C A^-1 C^T of the contact DOFs
/// (schur_complement.h): every unknown of the small dense problem is bounded.
void ContactSolver::condense()
{
  _schur = std::make_unique<SchurComplement>(_comm, _prefix, _A, _structure, _dofs);
  _vi_stage = std::make_unique<SolverStage>(_prefix + "contact");
  _vi_comm = PETSC_COMM_SELF;
  _K = _schur->matrix();
  const PetscInt m = _schur->size();
  _bounded.resize(m);
  for (PetscInt k = 0; k < m; ++k)
    _bounded[k] = static_cast<std::int32_t>(k);
  _bounded_gap.resize(m);
  _schur->gather(_set.gap.data(), _bounded_gap.data());
  VecCreateSeq(PETSC_COMM_SELF, m, &_x);
  // H is small and dense: LAPACK's factorisation, Cholesky when A is SPD.
  const std::string vi_prefix = _prefix + "contact_";
  set_default_option(vi_prefix + "ksp_type", "preonly");
  set_default_option(vi_prefix + "pc_type", _structure == Structure::spd ? "cholesky" : "lu");
  set_default_option(vi_prefix + "pc_factor_mat_solver_type", "petsc");
  make_bound_vectors();
}

/// The VI on the full system: only the contact DOFs are bounded.
void ContactSolver::pose_on_full_system(Vec layout)
{
  _vi_comm = _comm;
  _K = _A;
  _bounded = _dofs;
  _bounded_gap = _set.gap;
  VecDuplicate(layout, &_x);
  make_bound_vectors();
}

/// The residual and the bounds, unbounded until solve() sets the contact ones.
void ContactSolver::make_bound_vectors()
{
  VecDuplicate(_x, &_residual);
  VecDuplicate(_x, &_lower);
  VecDuplicate(_x, &_upper);
  VecDuplicate(_x, &_b_scaled);
  VecSet(_lower, PETSC_NINFINITY);
  VecSet(_upper, PETSC_INFINITY);
}

/// The semismooth Newton VI solver (SNES vinewtonrsls) and its defaults;
/// the user's -<vi_prefix>snes_* options override them.
void ContactSolver::create_snes(const std::string& vi_prefix)
{
  // Jacobian evaluations cost nothing (the matrix is constant); the
  // factorisation is built at the first Newton step and then reused ("-2":
  // rebuild once, then lag forever) until the inactive set changes, when
  // SNES VI resets the preconditioner itself (PETSc 3.18 virs.c,
  // SNESVIResetPCandKSP).
  PetscBool lag_given = PETSC_FALSE;
  PetscOptionsHasName(nullptr, vi_prefix.c_str(), "-snes_lag_preconditioner", &lag_given);
  _lag_by_default = !lag_given;
  PetscOptionsHasName(nullptr, vi_prefix.c_str(), "-snes_rtol", &_snes_rtol_given);
  set_default_option(vi_prefix + "snes_lag_preconditioner", "-2");
  set_default_option(vi_prefix + "snes_rtol", "1e-10");
  set_default_option(vi_prefix + "snes_stol", "1e-12");
  set_default_option(vi_prefix + "snes_max_it", "100");
  // F is linear and its matrix the exact Jacobian: the full semismooth
  // Newton step is exact on the current active set, and a backtracking
  // search only fails once the residual is at round-off.
  set_default_option(vi_prefix + "snes_linesearch_type", "basic");
  SNESCreate(_vi_comm, &_snes);
  SNESSetOptionsPrefix(_snes, vi_prefix.c_str());
  SNESSetType(_snes, SNESVINEWTONRSLS);
  SNESSetFunction(_snes, _residual, &ContactSolver::residual, this);
  SNESSetJacobian(_snes, _K, _K, &ContactSolver::jacobian, this);
  SNESVISetVariableBounds(_snes, _lower, _upper);
  SNESSetConvergenceTest(_snes, &ContactSolver::converged, this, nullptr);
  // At least one Newton step per solve: a step is an exact solve on the
  // active set, so the result never lags behind the load (a residual
  // already below the tolerance would otherwise leave x as it was).
  SNESSetForceIteration(_snes, PETSC_TRUE);
  SNESMonitorSet(_snes, &ContactSolver::monitor, this, nullptr);
}
std::string ContactSolver::method() const
{
  return _schur ? "condensed on " + std::to_string(_schur->size()) + " contact DOFs" : "full";
}

void ContactSolver::operator_changed()
{
  // H is formed again at the next solve; re-arm "rebuild once, then reuse"
  // (the lag is -1 after the first build).
  _schur_current = false;
  if (_lag_by_default)
    SNESSetLagPreconditioner(_snes, -2);
}

void ContactSolver::set_tolerance(double relative)
{
  if (!_preconditioner)
    return;
  KSP ksp;
  SNESGetKSP(_snes, &ksp);
  set_relative_tolerance(ksp, _prefix, relative);
  if (!_snes_rtol_given)
    SNESSetTolerances(_snes, PETSC_DEFAULT, relative, PETSC_DEFAULT, PETSC_DEFAULT, PETSC_DEFAULT);
}

std::vector<char> ContactSolver::active_contact_dofs(Vec x) const
{
  // PETSc's rule (SNESVIGetActiveSetIS): a DOF is active when it lies on a
  // bound to 1e-8 and F pushes it against that bound.
  Vec F = nullptr;
  SNESGetFunction(_snes, &F, nullptr, nullptr);
  const PetscScalar *X, *R, *lo, *up;
  VecGetArrayRead(x, &X);
  VecGetArrayRead(F, &R);
  VecGetArrayRead(_lower, &lo);
  VecGetArrayRead(_upper, &up);
  std::vector<char> active(_bounded.size());
  for (std::size_t k = 0; k < _bounded.size(); ++k)
  {
    const std::int32_t i = _bounded[k];
    active[k] = (X[i] <= lo[i] + 1e-8 and R[i] > 0) or (X[i] >= up[i] - 1e-8 and R[i] < 0);
  }
  VecRestoreArrayRead(x, &X);
  VecRestoreArrayRead(F, &R);
  VecRestoreArrayRead(_lower, &lo);
  VecRestoreArrayRead(_upper, &up);
  return active;
}

PetscErrorCode ContactSolver::monitor(SNES snes, PetscInt iteration, PetscReal, void* context)
{
  auto* self = static_cast<ContactSolver*>(context);
  if (iteration > 0)
  {
    // The set recorded before this step was the one the step used.
    int changed = self->_any_used and self->_pending != self->_used, any = 0;
    MPI_Allreduce(&changed, &any, 1, MPI_INT, MPI_MAX, self->_vi_comm);
    self->active_set_changes += any;
    self->_used = self->_pending;
    self->_any_used = true;
  }
  Vec x = nullptr;
  SNESGetSolution(snes, &x);
  self->_pending = self->active_contact_dofs(x);
  if (iteration > 0)
  {
    int differs = self->_pending != self->_used, any = 0;
    MPI_Allreduce(&differs, &any, 1, MPI_INT, MPI_MAX, self->_vi_comm);
    self->_set_repeated = !any;
    if (self->on_newton_step)
      self->on_newton_step(static_cast<int>(iteration));
  }
  return 0;
}

PetscErrorCode ContactSolver::stagnation(KSP ksp, PetscInt iteration, PetscReal rnorm, void* context)
{
  // A Newton step whose reduced system is singular (a body held in the
  // normal direction by one or two active nodes, see solve), or whose
  // right-hand side is round-off (the forced first step of a solve that
  // starts converged), makes the Krylov method stagnate. A converging step
  // takes tens of iterations (docs/performance.md); one that has not
  // reduced its residual by 1% over the last `stagnation_window` is stopped
  // (its iteration limit lowered to now: DIVERGED_ITS), and the solve
  // restarts from the clamped state. The limit is restored at the next
  // solve.
  auto* self = static_cast<ContactSolver*>(context);
  if (iteration == 0)
  {
    self->_residuals.clear();
    if (self->_lowered_from > 0)
      PetscCall(KSPSetTolerances(ksp, PETSC_DEFAULT, PETSC_DEFAULT, PETSC_DEFAULT, self->_lowered_from));
    self->_lowered_from = 0;
  }
  self->_residuals.push_back(rnorm);
  if (iteration >= stagnation_window and rnorm > 0.99 * self->_residuals[iteration - stagnation_window])
  {
    PetscReal rtol, atol, dtol;
    PetscCall(KSPGetTolerances(ksp, &rtol, &atol, &dtol, &self->_lowered_from));
    PetscCall(KSPSetTolerances(ksp, PETSC_DEFAULT, PETSC_DEFAULT, PETSC_DEFAULT, iteration));
  }
  return 0;
}

PetscErrorCode ContactSolver::converged(SNES snes, PetscInt iteration, PetscReal, PetscReal, PetscReal fnorm,
                                        SNESConvergedReason* reason, void* context)
{
  auto* self = static_cast<ContactSolver*>(context);
  PetscReal atol = 0, rtol = 0, stol = 0;
  PetscInt max_it = 0, max_f = 0;
  PetscCall(SNESGetTolerances(snes, &atol, &rtol, &stol, &max_it, &max_f));
  // PETSc's test for the VI methods (vi.c, SNESConvergedDefault_VI), with
  // at least one step taken (SNESSetForceIteration) ...
  *reason = SNES_CONVERGED_ITERATING;
  if (iteration == 0)
    self->_relative_target = rtol * fnorm;
  if (PetscIsInfOrNanReal(fnorm))
    *reason = SNES_DIVERGED_FNORM_NAN;
  else if (iteration > 0 and fnorm < atol)
    *reason = SNES_CONVERGED_FNORM_ABS;
  else if (iteration > 0 and fnorm < self->_relative_target)
    *reason = SNES_CONVERGED_FNORM_RELATIVE;
  // ... and the stopping rule of the primal-dual active set method: the
  // step solved F = 0 on the inactive set, and the active set at its result
  // is the one it used, so no DOF crosses its bound and every contact force
  // pushes the right way: x solves the VI (to the linear solver's
  // tolerance). F is linear, so this is the solution on that set even where
  // the residual's round-off (A x and b of very different sizes, pressures
  // in units of the displacement scale on the coupled system) lies above
  // atol, which the test above would never see met. SNES has no reason for
  // it; CONVERGED_ITS stands for "stopped by the method's own rule".
  else if (iteration > 0 and self->_set_repeated)
    *reason = SNES_CONVERGED_ITS;
  return 0;
}

ContactSolver::~ContactSolver()
{
  SNESDestroy(&_snes);
  for (Vec* v : {&_x, &_residual, &_lower, &_upper, &_b_scaled, &_force})
    VecDestroy(v);
}

// F(x) = K x - b/s: the gradient of the quadratic energy, in units of s.
PetscErrorCode ContactSolver::residual(SNES, Vec x, Vec F, void* context)
{
  auto* self = static_cast<ContactSolver*>(context);
  MatMult(self->_K, x, F);
  VecAXPY(F, -1.0, self->_b_scaled);
  return 0;
}

// The Jacobian is the constant matrix K (A, or H formed once per A).
PetscErrorCode ContactSolver::jacobian(SNES, Vec, Mat, Mat, void*) { return 0; }

double ContactSolver::displacement_scale(Vec x) const
{
  double local = 0;
  for (double g : _set.gap)
    local = std::max(local, g);
  const PetscScalar* X;
  VecGetArrayRead(x, &X);
  for (std::int32_t dof : _displacement_dofs)
    local = std::max(local, std::abs(X[dof]));
  VecRestoreArrayRead(x, &X);
  double global = 0;
  MPI_Allreduce(&local, &global, 1, MPI_DOUBLE, MPI_MAX, _comm);
  return global > 0 ? global : 1.0;
}

void ContactSolver::solve(Vec b, Vec x)
{
  if (_schur and !_schur_current)
  {
    _schur->assemble();
    _schur_current = true;
  }
  // SNESVI decides "on the bound" with an absolute tolerance (1e-8), so it
  // works on x / s with s the displacement scale (largest gap or |x|); the
  // residual K (x/s) - b/s has the same Jacobian K.
  _scale = displacement_scale(x);
  set_bounds();
  pose(b, x);
  SNESConvergedReason reason = run_snes();
  count_iterations(reason);
  if (reason < 0)
  {
    // A body held in the normal direction by the foundation alone is
    // semi-coercive: from a start where no contact DOF pushes on its bound
    // the reduced system is singular. Start again from the state with every
    // contact node on the foundation; there the contact forces say which
    // nodes to release.
    clamped_start();
    reason = run_snes();
    count_iterations(reason);
  }
  if (reason < 0)
    throw SolverError(std::string("the contact solver (SNES vinewtonrsls) did not converge: ")
                      + SNESConvergedReasons[reason]);
  VecScale(_x, _scale);
  if (_schur)
    _schur->extend(b, _x, x);
  else
    VecCopy(_x, x);
}

/// u.nu_F <= g_a with nu_F = sign e_axis: u_axis <= g_a or u_axis >= -g_a,
/// in units of the displacement scale.
void ContactSolver::set_bounds()
{
  PetscScalar *lo, *up;
  VecGetArray(_lower, &lo);
  VecGetArray(_upper, &up);
  for (std::size_t k = 0; k < _bounded.size(); ++k)
  {
    if (_set.sign > 0)
      up[_bounded[k]] = _bounded_gap[k] / _scale;
    else
      lo[_bounded[k]] = -_bounded_gap[k] / _scale;
  }
  VecRestoreArray(_lower, &lo);
  VecRestoreArray(_upper, &up);
}

/// The scaled load and start of the VI (on C alone when condensed: (H, g)
/// with y = x_C, schur_complement.h), and its absolute tolerance relative
/// to the load unless -snes_atol is given: scale-free.
void ContactSolver::pose(Vec b, Vec x)
{
  if (_schur)
  {
    _schur->condensed_load(b, _b_scaled);
    _schur->restrict_to_contact(x, _x);
  }
  else
  {
    VecCopy(b, _b_scaled);
    VecCopy(x, _x);
  }
  VecScale(_b_scaled, 1.0 / _scale);
  VecScale(_x, 1.0 / _scale);
  const char* prefix = nullptr;
  SNESGetOptionsPrefix(_snes, &prefix);
  PetscBool atol_given = PETSC_FALSE;
  PetscOptionsHasName(nullptr, prefix, "-snes_atol", &atol_given);
  if (!atol_given)
  {
    PetscReal bnorm = 0;
    VecNorm(_b_scaled, NORM_2, &bnorm);
    SNESSetTolerances(_snes, std::max(1e-10 * bnorm, 1e-300), PETSC_DEFAULT, PETSC_DEFAULT, PETSC_DEFAULT,
                      PETSC_DEFAULT);
  }
}

/// Every attempt's steps count, a failed Krylov solve's iterations too
/// (SNES leaves them out of its own count): they cost their time.
void ContactSolver::count_iterations(SNESConvergedReason reason)
{
  PetscInt its = 0, lits = 0, failed = 0;
  SNESGetIterationNumber(_snes, &its);
  SNESGetLinearSolveIterations(_snes, &lits);
  if (reason == SNES_DIVERGED_LINEAR_SOLVE)
  {
    KSP ksp;
    SNESGetKSP(_snes, &ksp);
    KSPGetIterationNumber(ksp, &failed);
  }
  newton_iterations += its;
  linear_iterations += lits + failed;
}

SNESConvergedReason ContactSolver::run_snes()
{
  std::optional<SolverStage::Guard> stage;
  if (_vi_stage)
    stage.emplace(*_vi_stage);
  if (PetscErrorCode ierr = SNESSolve(_snes, nullptr, _x); ierr != 0)
    throw SolverError("the contact solver (SNES vinewtonrsls) failed: PETSc error " + std::to_string(ierr));
  SNESConvergedReason reason;
  SNESGetConvergedReason(_snes, &reason);
  return reason;
}

void ContactSolver::clamped_start()
{
  // Every contact DOF on its bound; the other DOFs (none when condensed)
  // solve their equations: A x = b/s with the contact rows and columns
  // eliminated and the known values moved to the right-hand side.
  PetscInt start = 0;
  VecGetOwnershipRange(_x, &start, nullptr);
  std::vector<PetscInt> rows;
  const PetscScalar *lo, *up;
  VecGetArrayRead(_lower, &lo);
  VecGetArrayRead(_upper, &up);
  PetscScalar* x;
  VecGetArray(_x, &x);
  for (std::int32_t dof : _bounded)
  {
    rows.push_back(start + dof);
    x[dof] = _set.sign > 0 ? up[dof] : lo[dof];
  }
  VecRestoreArray(_x, &x);
  VecRestoreArrayRead(_lower, &lo);
  VecRestoreArrayRead(_upper, &up);
  if (_schur)
    return;
  // A (and the preconditioning matrix P, when it is another) with the
  // contact rows and columns made identity rows.
  auto clamped_copy = [&](Mat M, Vec rhs)
  {
    Mat C;
    MatDuplicate(M, MAT_COPY_VALUES, &C);
    MatNullSpace modes = nullptr; // for AMG: the duplicate does not keep it
    MatGetNearNullSpace(M, &modes);
    if (modes)
      MatSetNearNullSpace(C, modes);
    MatZeroRowsColumns(C, static_cast<PetscInt>(rows.size()), rows.data(), 1.0, rhs ? _x : nullptr, rhs);
    return C;
  };
  Vec rhs;
  VecDuplicate(_b_scaled, &rhs);
  VecCopy(_b_scaled, rhs);
  Mat A = clamped_copy(_A, rhs);
  Mat P = _P == _A ? A : clamped_copy(_P, nullptr);
  {
    LinearSolver clamped(_comm, _prefix, A, P, _structure, _fields);
    clamped.solve(_x, rhs);
  }
  if (P != A)
    MatDestroy(&P);
  MatDestroy(&A);
  VecDestroy(&rhs);
}

int ContactSolver::active_nodes(Vec x) const
{
  const double scale = displacement_scale(x);
  const PetscScalar* X;
  VecGetArrayRead(x, &X);
  int local = 0;
  for (std::size_t k = 0; k < _dofs.size(); ++k)
    local += _set.gap[k] - _set.sign * X[_dofs[k]] <= 1e-9 * scale;
  VecRestoreArrayRead(x, &X);
  int global = 0;
  MPI_Allreduce(&local, &global, 1, MPI_INT, MPI_SUM, _comm);
  return global;
}

ContactState ContactSolver::state(Vec x, Vec b, fem::Function<double>& pressure_out,
                                  fem::Function<double>& active_out)
{
  ContactState s;
  // Nodal contact force R = A x - b (the residual of the unconstrained
  // equations); the contact pressure is -R.nu_F / lumped measure.
  MatMult(_A, x, _force);
  VecAXPY(_force, -1.0, b);
  const PetscScalar *R, *X;
  VecGetArrayRead(_force, &R);
  VecGetArrayRead(x, &X);
  std::span<double> pc = pressure_out.x()->mutable_array();
  std::span<double> active = active_out.x()->mutable_array();
  std::fill(pc.begin(), pc.end(), 0.0);
  std::fill(active.begin(), active.end(), 0.0);

  std::vector<double> pressure(_dofs.size()), normal(_dofs.size());
  for (std::size_t k = 0; k < _dofs.size(); ++k)
  {
    normal[k] = _set.sign * X[_dofs[k]];
    pressure[k] = -_set.sign * R[_dofs[k]] / _set.lumped[k];
  }
  VecRestoreArrayRead(_force, &R);
  VecRestoreArrayRead(x, &X);
  s.gap_scale = displacement_scale(x);

  // A node is active when it lies on the foundation to round-off.
  double pen = -std::numeric_limits<double>::infinity(), comp = 0, force = 0;
  double pmax = -std::numeric_limits<double>::infinity(), pmin = std::numeric_limits<double>::infinity();
  int n_active = 0;
  for (std::size_t k = 0; k < _dofs.size(); ++k)
  {
    const double distance = _set.gap[k] - normal[k];
    const bool is_active = distance <= 1e-9 * s.gap_scale;
    n_active += is_active;
    pen = std::max(pen, -distance);
    comp = std::max(comp, std::abs(pressure[k] * distance));
    pmax = std::max(pmax, pressure[k]);
    pmin = std::min(pmin, pressure[k]);
    force += pressure[k] * _set.lumped[k];
    pc[_set.output_dofs[k]] = pressure[k];
    active[_set.output_dofs[k]] = is_active ? 1.0 : 0.0;
  }
  pressure_out.x()->scatter_fwd();
  active_out.x()->scatter_fwd();
  const int n_local[2] = {n_active, static_cast<int>(_dofs.size())};
  int n_global[2];
  MPI_Allreduce(n_local, n_global, 2, MPI_INT, MPI_SUM, _comm);
  s.active_nodes = n_global[0];
  s.contact_nodes = n_global[1];
  double maxes[4] = {pen, comp, pmax, -pmin}, gmax[4];
  MPI_Allreduce(maxes, gmax, 4, MPI_DOUBLE, MPI_MAX, _comm);
  s.max_penetration = gmax[0];
  s.max_complementarity = gmax[1];
  s.max_pressure = gmax[2];
  s.min_pressure = -gmax[3];
  MPI_Allreduce(&force, &s.total_force, 1, MPI_DOUBLE, MPI_SUM, _comm);
  return s;
}

} // namespace biotcontact
