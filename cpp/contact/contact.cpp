#include "contact/contact.h"

#include "contact/fault_pair.h"
#include "contact/foundation_pair.h"

#include "assembly/linear_algebra.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <dolfinx/fem/DirichletBC.h>
#include <dolfinx/fem/FunctionSpace.h>
#include <limits>
#include <map>
#include <optional>
#include <set>
#include <utility>

namespace biotcontact
{
using namespace dolfinx;

ContactSet locate_contact(const Scene& scene, const Domain& domain, const CompiledForms& forms,
                          std::shared_ptr<const fem::FunctionSpace> V)
{
  ContactSet c;
  c.dim = domain.dim();
  c.output_space = std::make_shared<fem::FunctionSpace>(V->sub({0})->collapse().first);
  c.dof_offset = V->dofmap()->index_map_bs() * V->dofmap()->index_map->local_range()[0];
  std::string error; // the first bad input on this rank
  add_foundation_pairs(scene, domain, forms, V, c, error);
  add_fault_pairs(scene, domain, forms, V, c, error);
  agree_on_error(error, domain.mesh->comm());
  return c;
}

namespace
{
/// What a friction that fails to converge most often means.
constexpr const char* no_equilibrium = " (a body that friction cannot hold has no quasi-static equilibrium)";

/// Reads -<prefix>contact_condensed through PETSc's options database, so
/// that -help lists it with this run's default.
PetscErrorCode read_condensed(MPI_Comm comm, const std::string& prefix, PetscBool fallback, PetscBool* condensed)
{
  PetscFunctionBeginUser;
  PetscOptionsBegin(comm, prefix.c_str(), "Contact solver (biotcontact)", nullptr);
  const std::string text = "pose the contact VI on the Schur complement of the contact DOFs (default with a "
                           "direct solver and at most "
                           + std::to_string(ContactSolver::max_condensed_dofs)
                           + " contact DOFs), else on the whole system";
  PetscCall(PetscOptionsBool("-contact_condensed", text.c_str(), "docs/user-guide.md", fallback, condensed, nullptr));
  PetscOptionsEnd();
  PetscFunctionReturn(0);
}

/// Whether the VI is posed on the Schur complement: -<prefix>contact_condensed,
/// by default when the system is solved directly, C is small enough and A
/// is not `changing`.
bool use_condensation(MPI_Comm comm, const std::string& prefix, Method method, PetscInt contact_dofs, bool changing)
{
  // Forming H takes m solves: cheap back-solves of a factorisation, but m
  // full Krylov solves with an iterative method, and m more at each change
  // of A.
  const bool fallback
      = method == Method::direct and contact_dofs <= ContactSolver::max_condensed_dofs and !changing;
  PetscBool condensed = fallback ? PETSC_TRUE : PETSC_FALSE;
  if (read_condensed(comm, prefix, condensed, &condensed) != 0)
    throw OptionsError("-" + prefix + "contact_condensed: not a boolean (true or false)");
  return condensed;
}
/// Whether any rank has a frictional constraint (collective).
bool any_frictional(const ContactSet& set, MPI_Comm comm)
{
  int local = std::any_of(set.frictional.begin(), set.frictional.end(), [](char f) { return f != 0; }), any = 0;
  MPI_Allreduce(&local, &any, 1, MPI_INT, MPI_MAX, comm);
  return any;
}

/// Every rank's constraints on every rank, in rank order (collective): a
/// record of plain values, gathered as bytes.
std::vector<FrictionalConstraint> all_gather_constraints(const std::vector<FrictionalConstraint>& mine, MPI_Comm comm)
{
  static_assert(std::is_trivially_copyable_v<FrictionalConstraint>);
  int ranks = 1;
  MPI_Comm_size(comm, &ranks);
  const int bytes = static_cast<int>(mine.size() * sizeof(FrictionalConstraint));
  std::vector<int> counts(ranks), starts(ranks + 1, 0);
  MPI_Allgather(&bytes, 1, MPI_INT, counts.data(), 1, MPI_INT, comm);
  for (int r = 0; r < ranks; ++r)
    starts[r + 1] = starts[r] + counts[r];
  std::vector<FrictionalConstraint> all(starts[ranks] / sizeof(FrictionalConstraint));
  MPI_Allgatherv(mine.data(), bytes, MPI_BYTE, all.data(), counts.data(), starts.data(), MPI_BYTE, comm);
  return all;
}
} // namespace

ContactSolver::ContactSolver(MPI_Comm comm, const SystemLayout& system, Method method, ContactOperators operators,
                             ContactUnknowns unknowns)
    : _comm(comm), _A(operators.A), _P(operators.P), _fields(system.fields), _structure(system.structure),
      _prefix(system.prefix), _set(std::move(unknowns.set)), _displacement_dofs(std::move(unknowns.displacement_dofs)),
      _separate_rows(std::move(unknowns.separate_rows))
{
  const std::string& prefix = system.prefix;
  const Vec layout = unknowns.layout;
  for (std::int32_t dof : _set.dofs)
    _dofs.push_back(_displacement_dofs.at(dof));
  // MAT_SPD carries over to the inactive-set submatrices: Cholesky there.
  if (_structure == Structure::spd)
    MatSetOption(_A, MAT_SPD, PETSC_TRUE);
  VecDuplicate(layout, &_force);
  VecDuplicate(layout, &_x_start);
  VecDuplicate(layout, &_x_start_vi);
  VecSet(_x_start, 0.0);
  make_change_of_variables(layout);

  long local_dofs = static_cast<long>(contact_dofs().size()), all_dofs = 0;
  MPI_Allreduce(&local_dofs, &all_dofs, 1, MPI_LONG, MPI_SUM, comm);
  const bool condensed = use_condensation(comm, prefix, method, all_dofs, operators.changing);
  if (condensed)
    condense();
  else
    pose_on_full_system(layout);
  make_friction();
  const std::string vi_prefix = condensed ? prefix + "contact_" : prefix;
  if (_J and !condensed)
    unsymmetric_jacobian_options(prefix);
  _preconditioner_on_P = !condensed and method == Method::iterative;
  create_snes(vi_prefix);
  if (_preconditioner_on_P)
  {
    _preconditioner = std::make_unique<InactiveSetPreconditioner>(_snes, _P_vi, _fields, prefix);
    KSP ksp;
    SNESGetKSP(_snes, &ksp);
    _convergence->watch(ksp);
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
  const std::vector<std::int32_t> dofs = contact_dofs();
  _schur = std::make_unique<SchurComplement>(_comm, _prefix, _A_vi, _structure, dofs);
  _vi_stage = std::make_unique<SolverStage>(_prefix + "contact");
  _vi_comm = PETSC_COMM_SELF;
  _K = _schur->matrix();
  const PetscInt m = _schur->size();
  // Each rank's constraints come first among its contact DOFs, its
  // tangential ones (friction) after them: the bounded DOFs of H are the
  // constraints'.
  std::vector<double> bounded(dofs.size(), 0.0), gap(dofs.size(), 0.0), sign(dofs.size(), 0.0);
  for (std::size_t k = 0; k < _dofs.size(); ++k)
    bounded[k] = 1, gap[k] = _set.gap[k], sign[k] = _set.sign[k];
  std::vector<double> all_bounded(m), all_gap(m), all_sign(m);
  _schur->gather(bounded.data(), all_bounded.data());
  _schur->gather(gap.data(), all_gap.data());
  _schur->gather(sign.data(), all_sign.data());
  for (PetscInt k = 0; k < m; ++k)
    if (all_bounded[k] > 0)
    {
      _bounded.push_back(static_cast<std::int32_t>(k));
      _bounded_gap.push_back(all_gap[k]);
      _bounded_sign.push_back(all_sign[k]);
    }
  VecCreateSeq(PETSC_COMM_SELF, m, &_x);
  // H is small and dense: LAPACK's factorisation, Cholesky when A is SPD
  // but for the Jacobian of friction, which is not symmetric.
  const std::string vi_prefix = _prefix + "contact_";
  set_default_option(vi_prefix + "ksp_type", "preonly");
  const bool symmetric = _structure == Structure::spd and !any_frictional(_set, _comm);
  set_default_option(vi_prefix + "pc_type", symmetric ? "cholesky" : "lu");
  set_default_option(vi_prefix + "pc_factor_mat_solver_type", "petsc");
  make_bound_vectors();
}

std::vector<std::int32_t> ContactSolver::contact_dofs() const
{
  std::vector<std::int32_t> dofs = _dofs;
  for (std::size_t k = 0; k < _dofs.size(); ++k)
    if (_set.frictional[k])
      for (int r = 1; r < _set.dim; ++r)
        dofs.push_back(_displacement_dofs.at(_set.dofs[k] + r));
  return dofs;
}

/// The frictional constraints in the VI's numbering: on the full system
/// this rank's, at their local positions; condensed, every rank's at their
/// places in H (each rank's contact DOFs from offset(), contact_dofs()'s
/// order), gathered to every rank.
void ContactSolver::make_friction()
{
  const int d = _set.dim;
  const PetscInt first = _schur ? _schur->offset() : 0;
  std::vector<FrictionalConstraint> mine;
  PetscInt next = static_cast<PetscInt>(_dofs.size());
  for (std::size_t k = 0; k < _dofs.size(); ++k)
  {
    if (!_set.frictional[k])
      continue;
    FrictionalConstraint f;
    f.normal = _schur ? first + static_cast<PetscInt>(k) : _dofs[k];
    for (int r = 1; r < d; ++r, ++next)
      f.tangential[r - 1] = _schur ? first + next : _displacement_dofs[_set.dofs[k] + r];
    f.sign = _set.sign[k], f.gap = _set.gap[k], f.lumped = _set.lumped[k];
    f.law = _set.laws[_set.boundary[k]];
    mine.push_back(f);
  }
  _friction = _schur ? all_gather_constraints(mine, _comm) : mine;
  if (!any_frictional(_set, _comm))
    return;
  for (Vec* v : {&_x_reference, &_stiffness, &_work})
    VecDuplicate(_x, v);
  VecSet(_x_reference, 0.0);
  MatDuplicate(_K, MAT_COPY_VALUES, &_J);
  // Its tangential rows are combinations of the constraint's own rows of K
  // (friction_jacobian), inside K's pattern where the rows of a node share
  // it; allowed to grow where they do not.
  if (!_schur)
    MatSetOption(_J, MAT_NEW_NONZERO_ALLOCATION_ERR, PETSC_FALSE);
  MatSetOption(_J, MAT_SPD, PETSC_FALSE);
  MatSetOption(_J, MAT_SYMMETRIC, PETSC_FALSE);
}

/// The VI on the full system: only the contact DOFs are bounded.
void ContactSolver::pose_on_full_system(Vec layout)
{
  _vi_comm = _comm;
  _K = _A_vi;
  _bounded = _dofs;
  _bounded_gap = _set.gap;
  _bounded_sign.assign(_set.sign.begin(), _set.sign.end());
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
  // With friction the Jacobian changes every step: no lag for a
  // factorisation of it. The iterative path's preconditioner is built from
  // P and the inactive set alone (inactive_set_preconditioner.h), not from
  // the Jacobian: it is reused across Newton steps there too.
  set_default_option(vi_prefix + "snes_lag_preconditioner", lag_preconditioner() ? "-2" : "1");
  set_default_option(vi_prefix + "snes_rtol", "1e-10");
  set_default_option(vi_prefix + "snes_stol", "1e-12");
  set_default_option(vi_prefix + "snes_max_it", "100");
  // F is linear and its matrix the exact Jacobian: the full semismooth
  // Newton step is exact on the current active set, and a backtracking
  // search only fails once the residual is at round-off.
  // With friction F is semismooth, and full steps can overshoot where a
  // constraint changes state: a backtracking search. But not with separate
  // rows: the search's merit ||F||, the forces' (N), is blind to them (the
  // coupled system's mass balances, m^3/s); with the forces at round-off
  // it shrank their step to nothing (a conduit fault's p_f,
  // test_conduit_monolithic).
  // Condensed, the VI's unknown is the contact DOFs alone.
  _convergence = std::make_unique<ContactConvergence>(
      _vi_comm, VIBounds{_lower, _upper, _bounded},
      _schur ? std::vector<std::int32_t>{} : std::move(_separate_rows));
  const bool backtrack = _J and !_convergence->has_separate_rows();
  set_default_option(vi_prefix + "snes_linesearch_type", backtrack ? "bt" : "basic");
  // No cap on the step's length (PETSc's 1e8): x is in units of the
  // displacement scale, so the pressures of the coupled system run to 1e10
  // and more, and a capped step crawls (a conduit fault's p_f moved 0.1 %
  // of its way per solve).
  set_default_option(vi_prefix + "snes_linesearch_maxstep", "1e300");
  SNESCreate(_vi_comm, &_snes);
  SNESSetOptionsPrefix(_snes, vi_prefix.c_str());
  SNESSetType(_snes, SNESVINEWTONRSLS);
  SNESSetFunction(_snes, _residual, &ContactSolver::residual, this);
  SNESSetJacobian(_snes, _J ? _J : _K, _J ? _J : _K, &ContactSolver::jacobian, this);
  SNESVISetVariableBounds(_snes, _lower, _upper);
  _convergence->attach(_snes, _b_scaled, _J != nullptr);
  // At least one Newton step per solve: a step is an exact solve on the
  // active set, so the result never lags behind the load (a residual
  // already below the tolerance would otherwise leave x as it was).
  // (Not with the backtracking search of friction: its F is not
  // linear, the residual decides, and the search fails on a zero step.)
  SNESSetForceIteration(_snes, backtrack ? PETSC_FALSE : PETSC_TRUE);
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
  _change_current = false;
  if (_lag_by_default and lag_preconditioner())
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





ContactSolver::~ContactSolver()
{
  SNESDestroy(&_snes);
  for (Vec* v : {&_x, &_residual, &_lower, &_upper, &_b_scaled, &_force, &_x_vi, &_b_vi, &_x_reference, &_stiffness,
                 &_work, &_x_start, &_x_start_vi})
    VecDestroy(v);
  MatDestroy(&_J);
  if (_change)
  {
    if (_P_vi != _A_vi)
      MatDestroy(&_P_vi);
    MatDestroy(&_A_vi);
  }
}

// F(x) = K x - b/s: the gradient of the quadratic energy, in units of s;
// with friction its frictional constraints' tangential rows carry the
// return map (friction.h).
PetscErrorCode ContactSolver::residual(SNES, Vec x, Vec F, void* context)
{
  auto* self = static_cast<ContactSolver*>(context);
  PetscCall(MatMult(self->_K, x, F));
  PetscCall(VecAXPY(F, -1.0, self->_b_scaled));
  if (self->_J)
    PetscCall(self->add_friction(x, F));
  return 0;
}

// The Jacobian is the constant matrix K (A, or H formed once per A); with
// friction the generalised Jacobian of its rows (friction_jacobian).
PetscErrorCode ContactSolver::jacobian(SNES, Vec x, Mat, Mat, void* context)
{
  auto* self = static_cast<ContactSolver*>(context);
  if (!self->_J)
    return 0;
  PetscCall(MatMult(self->_K, x, self->_work));
  PetscCall(VecAXPY(self->_work, -1.0, self->_b_scaled));
  const PetscScalar *X, *R, *start, *c;
  PetscCall(VecGetArrayRead(x, &X));
  PetscCall(VecGetArrayRead(self->_work, &R));
  PetscCall(VecGetArrayRead(self->_x_reference, &start));
  PetscCall(VecGetArrayRead(self->_stiffness, &c));
  PetscCall(friction_jacobian(self->_friction, {X, R, start, c, self->_scale, self->_set.dim - 1}, self->_K, self->_J));
  PetscCall(VecRestoreArrayRead(x, &X));
  PetscCall(VecRestoreArrayRead(self->_work, &R));
  PetscCall(VecRestoreArrayRead(self->_x_reference, &start));
  PetscCall(VecRestoreArrayRead(self->_stiffness, &c));
  return 0;
}

PetscErrorCode ContactSolver::add_friction(Vec x, Vec F) const
{
  const PetscScalar *X, *start, *c;
  PetscScalar* R;
  PetscFunctionBeginUser;
  PetscCall(VecGetArrayRead(x, &X));
  PetscCall(VecGetArray(F, &R));
  PetscCall(VecGetArrayRead(_x_reference, &start));
  PetscCall(VecGetArrayRead(_stiffness, &c));
  add_friction_forces(_friction, {X, R, start, c, _scale, _set.dim - 1}, R);
  PetscCall(VecRestoreArrayRead(x, &X));
  PetscCall(VecRestoreArray(F, &R));
  PetscCall(VecRestoreArrayRead(_x_reference, &start));
  PetscCall(VecRestoreArrayRead(_stiffness, &c));
  PetscFunctionReturn(0);
}

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
  change_operators();
  Vec b_vi = b;
  if (_change)
  {
    _change->dual(b, _b_vi);
    b_vi = _b_vi;
  }
  Vec x_vi = to_vi(x, _x_vi);
  if (_schur and !_schur_current)
  {
    _schur->assemble();
    _schur_current = true;
  }
  // SNESVI decides "on the bound" with an absolute tolerance (1e-8), so it
  // works on x / s with s the displacement scale (largest gap or |x|); the
  // residual K (x/s) - b/s has the same Jacobian K.
  _scale = displacement_scale(x_vi);
  set_bounds();
  pose(b_vi, x_vi);
  if (_J) // the stiffness that turns a slip increment into a trial force
    check_petsc(MatGetDiagonal(_K, _stiffness), "friction: the diagonal of the contact matrix");
  solve_vi();
  VecScale(_x, _scale);
  if (_schur)
    _schur->extend(b_vi, _x, x_vi);
  else
    VecCopy(_x, x_vi);
  if (_change)
    _change->backward(x_vi, x);
}

void ContactSolver::set_slip_reference(Vec x)
{
  VecCopy(x, _x_start);
  if (!_x_reference)
    return;
  Vec x_vi = to_vi(x, _x_vi);
  if (_schur)
    _schur->restrict_to_contact(x_vi, _x_reference);
  else
    VecCopy(x_vi, _x_reference);
}

void ContactSolver::solve_vi()
{
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
                      + SNESConvergedReasons[reason] + (_J ? no_equilibrium : ""));
}

/// u.nu_F = sign x'[dof] <= g_a: x'[dof] <= g_a or x'[dof] >= -g_a, in
/// units of the displacement scale.
void ContactSolver::set_bounds()
{
  PetscScalar *lo, *up;
  VecGetArray(_lower, &lo);
  VecGetArray(_upper, &up);
  for (std::size_t k = 0; k < _bounded.size(); ++k)
  {
    if (_bounded_sign[k] > 0)
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
    // With friction the residual decides the last step (F is not
    // linear): tighter, Newton's last steps are quadratic.
    const double relative = _J ? 1e-12 : 1e-10;
    SNESSetTolerances(_snes, std::max(relative * bnorm, 1e-300), PETSC_DEFAULT, PETSC_DEFAULT, PETSC_DEFAULT,
                      PETSC_DEFAULT);
  }
  _convergence->pose();
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
  for (std::size_t k = 0; k < _bounded.size(); ++k)
  {
    const std::int32_t dof = _bounded[k];
    rows.push_back(start + dof);
    x[dof] = _bounded_sign[k] > 0 ? up[dof] : lo[dof];
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
  Mat A = clamped_copy(_A_vi, rhs);
  Mat P = _P_vi == _A_vi ? A : clamped_copy(_P_vi, nullptr);
  {
    LinearSolver clamped(_comm, _prefix, A, P, _structure, _fields);
    clamped.solve(_x, rhs);
  }
  if (P != A)
    MatDestroy(&P);
  MatDestroy(&A);
  VecDestroy(&rhs);
}

void ContactSolver::make_change_of_variables(Vec layout)
{
  _A_vi = _A;
  _P_vi = _P;
  long local = static_cast<long>(_set.blocks.size()), global = 0;
  MPI_Allreduce(&local, &global, 1, MPI_LONG, MPI_SUM, _comm);
  if (global == 0)
    return;
  std::vector<std::int64_t> requested;
  for (const ContactBlock& block : _set.blocks)
    requested.insert(requested.end(), block.dofs.begin(), block.dofs.end());
  const std::vector<PetscInt> positions = solved_positions(requested, layout);
  std::vector<ChangeOfVariables::Block> blocks;
  std::size_t next = 0;
  for (const ContactBlock& block : _set.blocks)
  {
    ChangeOfVariables::Block b{{}, block.T};
    for (std::size_t i = 0; i < block.dofs.size(); ++i)
      b.dofs.push_back(positions[next++]);
    blocks.push_back(std::move(b));
  }
  _change = std::make_unique<ChangeOfVariables>(_A, blocks, _structure == Structure::spd);
  _A_vi = nullptr;
  _change->congruence(_A, &_A_vi);
  if (_P != _A)
  {
    _P_vi = nullptr;
    _change->congruence(_P, &_P_vi);
  }
  else
    _P_vi = _A_vi;
  _change_current = true;
  VecDuplicate(layout, &_x_vi);
  VecDuplicate(layout, &_b_vi);
  // The rigid-body modes of a field (the displacement of the coupled
  // system) change with its DOFs.
  for (Field& f : _fields)
    if (f.near_nullspace)
      f.near_nullspace = own(_change->transformed(f.near_nullspace.get(), &f.dofs, layout));
}

std::vector<PetscInt> ContactSolver::solved_positions(const std::vector<std::int64_t>& dofs, Vec layout) const
{
  // Each rank answers for the DOFs it owns; a fault's other face may be
  // owned by another rank, so every request goes to every rank (they are
  // the few DOFs of the transformed nodes).
  PetscInt start = 0;
  VecGetOwnershipRange(layout, &start, nullptr);
  const auto owned = static_cast<std::int64_t>(_displacement_dofs.size());
  const Gathered requests = all_gather(dofs, _comm);
  const std::vector<std::int64_t>& all = requests.values;
  std::vector<std::int64_t> answer(all.size(), -1);
  for (std::size_t k = 0; k < all.size(); ++k)
    if (const std::int64_t i = all[k] - _set.dof_offset; i >= 0 and i < owned)
      answer[k] = start + _displacement_dofs[i];
  MPI_Allreduce(MPI_IN_PLACE, answer.data(), static_cast<int>(answer.size()), MPI_INT64_T, MPI_MAX, _comm);
  int rank = 0;
  MPI_Comm_rank(_comm, &rank);
  return std::vector<PetscInt>(answer.begin() + requests.offsets[rank], answer.begin() + requests.offsets[rank + 1]);
}

void ContactSolver::change_operators()
{
  if (!_change or _change_current)
    return;
  _change->congruence(_A, &_A_vi);
  if (_P_vi != _A_vi)
    _change->congruence(_P, &_P_vi);
  _change_current = true;
}

Vec ContactSolver::to_vi(Vec x, Vec work) const
{
  if (!_change)
    return x;
  _change->forward(x, work);
  return work;
}

std::vector<double> ContactSolver::distances(Vec x) const
{
  const PetscScalar* X;
  Vec x_vi = to_vi(x, _x_vi);
  VecGetArrayRead(x_vi, &X);
  std::vector<double> distance(_dofs.size());
  for (std::size_t k = 0; k < _dofs.size(); ++k)
    distance[k] = _set.gap[k] - _set.sign[k] * X[_dofs[k]];
  VecRestoreArrayRead(x_vi, &X);
  return distance;
}

ActiveSet ContactSolver::active_set(Vec x) const
{
  const double scale = displacement_scale(x);
  ActiveSet set;
  for (double distance : distances(x))
    set.flags.push_back(on_foundation(distance, scale));
  int local = static_cast<int>(std::count(set.flags.begin(), set.flags.end(), 1));
  MPI_Allreduce(&local, &set.nodes, 1, MPI_INT, MPI_SUM, _comm);
  return set;
}



ContactState ContactSolver::state(Vec x, Vec b, fem::Function<double>& pressure_out,
                                  fem::Function<double>& active_out)
{
  const std::vector<double> distance = distances(x);
  // Nodal contact force R = A x - b (the residual of the unconstrained
  // equations), in the new variables R' = T^{-T} R: the multiplier of each
  // constraint; the contact pressure is -R'[dof] sign / lumped measure.
  MatMult(_A, x, _force);
  VecAXPY(_force, -1.0, b);
  Vec force = _force;
  if (_change)
  {
    _change->dual(_force, _b_vi);
    force = _b_vi;
  }
  Vec x_vi = to_vi(x, _x_vi), start_vi = to_vi(_x_start, _x_start_vi);
  const PetscScalar *X, *start, *R;
  VecGetArrayRead(x_vi, &X);
  VecGetArrayRead(start_vi, &start);
  VecGetArrayRead(force, &R);
  std::vector<double> pressure(_dofs.size());
  for (std::size_t k = 0; k < _dofs.size(); ++k)
    pressure[k] = -_set.sign[k] * R[_dofs[k]] / _set.lumped[k];
  const ContactMeasurement measured{_set, _displacement_dofs, distance, pressure, displacement_scale(x), X, start, R};
  ContactState s = contact_state(measured, {pressure_out, active_out}, _comm);
  VecRestoreArrayRead(x_vi, &X);
  VecRestoreArrayRead(start_vi, &start);
  VecRestoreArrayRead(force, &R);
  return s;
}





} // namespace biotcontact
