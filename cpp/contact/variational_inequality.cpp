#include "contact/variational_inequality.h"

#include "contact/factorization_reuse.h"
#include "solvers/options.h"
#include "solvers/shared_outcome.h"

#include <algorithm>

namespace biotcontact
{

VariationalInequality::VariationalInequality(VIProblem problem, const std::optional<WholeSystem>& whole)
    : _p(std::move(problem)), _whole(whole)
{
  check_petsc(VecDuplicate(_p.layout, &_y), "contact solver: VecDuplicate");
  for (Vec* v : {&_b, &_residual, &_lower, &_upper, &_elastic, &_elastic_at})
    check_petsc(VecDuplicate(_y, v), "contact solver: VecDuplicate");
  // Unbounded until solve() sets the contact bounds.
  check_petsc(VecSet(_lower, PETSC_NINFINITY), "contact solver: VecSet");
  check_petsc(VecSet(_upper, PETSC_INFINITY), "contact solver: VecSet");
  if (!_p.stage.empty())
    _stage = std::make_unique<SolverStage>(_p.stage);
  if (_p.frictional)
    make_friction_operators();
  if (_J and _whole)
    unsymmetric_jacobian_options(_p.prefix);
  // A reduced system that CHOLMOD finds singular is answered by the clamped
  // start (run_snes): no warning on the terminal.
  if (_whole)
    set_default_option(_p.prefix + "mat_cholmod_print", "0");
  // Condensed, the VI's unknown is the contact DOFs alone: no separate rows.
  _convergence = std::make_unique<ContactConvergence>(_p.comm, VIBounds{_lower, _upper, _p.bounded},
                                                      std::move(_p.separate_rows));
  if (_whole and _whole->method == Method::iterative and is_coupled(_whole->layout.fields))
    _balanced = std::make_unique<BalancedRows>(_p.K, _whole->layout.fields, _p.comm);
  create_snes();
  set_from_options();
}

VariationalInequality::~VariationalInequality()
{
  check_petsc(SNESDestroy(&_snes), "contact solver: SNESDestroy");
  for (Vec* v : {&_y, &_b, &_residual, &_lower, &_upper, &_y_reference, &_stiffness, &_elastic, &_elastic_at})
    check_petsc(VecDestroy(v), "contact solver: VecDestroy");
  check_petsc(MatDestroy(&_J), "contact solver: MatDestroy");
}

/// The Jacobian of friction and its vectors (on every rank of the VI: the
/// duplicates are collective).
void VariationalInequality::make_friction_operators()
{
  for (Vec* v : {&_y_reference, &_stiffness})
    check_petsc(VecDuplicate(_y, v), "contact solver: VecDuplicate");
  check_petsc(VecSet(_y_reference, 0.0), "contact solver: VecSet");
  check_petsc(MatDuplicate(_p.K, MAT_COPY_VALUES, &_J), "contact solver: MatDuplicate");
  // Its tangential rows are combinations of the constraint's own rows of K
  // (friction_jacobian), inside K's pattern where the rows of a node share
  // it; allowed to grow where they do not.
  if (_whole)
    check_petsc(MatSetOption(_J, MAT_NEW_NONZERO_ALLOCATION_ERR, PETSC_FALSE), "contact solver: MatSetOption");
  check_petsc(MatSetOption(_J, MAT_SPD, PETSC_FALSE), "contact solver: MatSetOption");
  check_petsc(MatSetOption(_J, MAT_SYMMETRIC, PETSC_FALSE), "contact solver: MatSetOption");
}

/// The semismooth Newton VI solver (SNES vinewtonrsls) and its defaults;
/// the user's -<prefix>snes_* options override them.
void VariationalInequality::create_snes()
{
  const std::string& prefix = _p.prefix;
  // The factorisation is built at the first Newton step and then reused
  // ("-2": rebuild once, then lag forever) until the inactive set changes,
  // when SNES VI resets the preconditioner itself (PETSc 3.18 virs.c,
  // SNESVIResetPCandKSP), or the Jacobian changes: K reassembled
  // (operator_changed) or, with friction, its rows' weights (jacobian).
  PetscBool lag_given = PETSC_FALSE;
  check_petsc(PetscOptionsHasName(nullptr, prefix.c_str(), "-snes_lag_preconditioner", &lag_given), "contact solver: PetscOptionsHasName");
  _lag_by_default = !lag_given;
  check_petsc(PetscOptionsHasName(nullptr, prefix.c_str(), "-snes_rtol", &_snes_rtol_given), "contact solver: PetscOptionsHasName");
  set_default_option(prefix + "snes_lag_preconditioner", "-2");
  set_default_option(prefix + "snes_rtol", "1e-10");
  set_default_option(prefix + "snes_stol", "1e-12");
  set_default_option(prefix + "snes_max_it", "100");
  // F is linear and K its exact Jacobian: a full step is exact on the
  // active set (a backtracking search only fails at round-off). With
  // friction F is semismooth and full steps can overshoot where a
  // constraint changes state: a backtracking search, but not with separate
  // rows, to which its merit ||F|| (forces, N) is blind: with the forces at
  // round-off it shrank a conduit fault's p_f step to nothing.
  const bool backtrack = _J and !_convergence->has_separate_rows();
  set_default_option(prefix + "snes_linesearch_type", backtrack ? "bt" : "basic");
  // No cap on the step's length (PETSc's 1e8): y is in units of the
  // displacement scale, so the pressures of the coupled system run to 1e10
  // and more, and a capped step crawls (a conduit fault's p_f moved 0.1 %
  // of its way per solve).
  set_default_option(prefix + "snes_linesearch_maxstep", "1e300");
  check_petsc(SNESCreate(_p.comm, &_snes), "contact solver: SNESCreate");
  check_petsc(SNESSetOptionsPrefix(_snes, prefix.c_str()), "contact solver: SNESSetOptionsPrefix");
  check_petsc(SNESSetType(_snes, SNESVINEWTONRSLS), "contact solver: SNESSetType");
  check_petsc(SNESSetFunction(_snes, _residual, &VariationalInequality::residual, this), "contact solver: SNESSetFunction");
  Mat J = _balanced ? _balanced->jacobian() : _J ? _J : _p.K;
  check_petsc(SNESSetJacobian(_snes, J, J, &VariationalInequality::jacobian, this), "contact solver: SNESSetJacobian");
  check_petsc(SNESVISetVariableBounds(_snes, _lower, _upper), "contact solver: SNESVISetVariableBounds");
  _convergence->attach(_snes, tested_load(), _J != nullptr);
  _convergence->measure_round_off(_p.K, _balanced ? _balanced->weights() : nullptr);
  // At least one Newton step per solve: a step is an exact solve on the
  // active set, so the result never lags behind the load (a residual
  // already below the tolerance would otherwise leave y as it was).
  // (Not with the backtracking search of friction: its F is not
  // linear, the residual decides, and the search fails on a zero step.)
  check_petsc(SNESSetForceIteration(_snes, backtrack ? PETSC_FALSE : PETSC_TRUE), "contact solver: SNESSetForceIteration");
}

void VariationalInequality::set_from_options()
{
  if (_whole and _whole->method == Method::iterative)
  {
    _preconditioner = std::make_unique<InactiveSetPreconditioner>(_snes, _whole->P, _whole->layout.fields,
                                                                  _balanced ? _balanced->weights() : nullptr,
                                                                  _whole->layout.prefix);
    KSP ksp;
    check_petsc(SNESGetKSP(_snes, &ksp), "contact solver: SNESGetKSP");
    _convergence->watch(ksp);
    set_tolerance(iterative_tolerance);
  }
  if (PetscErrorCode ierr = SNESSetFromOptions(_snes); ierr != 0)
    throw OptionsError("the PETSc options of " + system_name(_p.system_prefix)
                       + " contact solver do not make a solver: " + petsc_error_text(ierr));
  if (!_whole or _whole->method != Method::direct)
    return;
  if (_p.tangents == 2 and (_J or _p.changing))
  {
    if (_lag_by_default and !given_by_user(_p.prefix + "ksp_type"))
      reuse_factorization();
  }
  else if (_p.changing or _J)
    // A 2D conduit fault's K changes at every solve, where GMRES on the
    // last factorisation took 15-30 back-solves a Newton step, more than a
    // factorisation with a quick analysis costs in 2D: each change is
    // factorised (docs/performance.md, "thirty-fourth session"); friction's
    // J changes with the inactive set and the slip states, METIS's analysis
    // took 2.1 of 10.6 s of the 50-fracture network ("fortieth session").
    analyse_quickly(_p.prefix, _p.K);
}

std::string VariationalInequality::solver_name() const
{
  SNESType type = nullptr;
  check_petsc(SNESGetType(_snes, &type), "contact solver: SNESGetType");
  return std::string("the contact solver (SNES ") + (type ? type : "without a type") + ")";
}

void VariationalInequality::reuse_factorization()
{
  // In 3D a slipping pair's rows of J turn with its slip at every Newton
  // step, and a conduit fault's rows of K follow its apertures from solve
  // to solve, while the rest of K and the inactive set stay, and a
  // factorisation costs about 100 back-solves (97,006 unknowns: 9.2 s
  // against 0.07 s): the factorisation of an earlier J preconditions GMRES
  // on the new one (reuse_options), else the Jacobian is factorised anew
  // (refactorised; theory.md, "Friction").
  _reuse_factorization = true;
  _reuse_options = reuse_options(_p.prefix);
}

void VariationalInequality::operator_changed()
{
  // Re-arm "rebuild once, then reuse" (the lag is -1 after the first build).
  _jacobian_weights.clear();
  if (_balanced)
    _balanced->operator_changed();
  if (_lag_by_default)
    check_petsc(SNESSetLagPreconditioner(_snes, -2), "contact solver: SNESSetLagPreconditioner");
}

void VariationalInequality::operator_nudged()
{
  if (!_reuse_factorization)
    return operator_changed();
  _jacobian_weights.clear(); // friction's J is built from the new K
}

long VariationalInequality::factorizations() const
{
  SolverStatistics s;
  if (_stage)
    _stage->read(s);
  return s.setups;
}

void VariationalInequality::set_tolerance(double relative)
{
  if (!_preconditioner)
    return;
  KSP ksp;
  check_petsc(SNESGetKSP(_snes, &ksp), "contact solver: SNESGetKSP");
  set_relative_tolerance(ksp, _whole->layout.prefix, relative);
  if (!_snes_rtol_given)
    check_petsc(SNESSetTolerances(_snes, PETSC_DEFAULT, relative, PETSC_DEFAULT, PETSC_DEFAULT, PETSC_DEFAULT), "contact solver: SNESSetTolerances");
}

void VariationalInequality::solve(double scale)
{
  std::optional<KrylovOnReuse> krylov;
  if (_reuse_factorization)
    krylov.emplace(_snes, _reuse_options);
  SNESConvergedReason reason = first_attempt(scale);
  if (reason == SNES_DIVERGED_LINEAR_SOLVE and _reusing)
    reason = refactorised();
  if (reason < 0)
  {
    // A body held normally by the foundation alone is semi-coercive: from a
    // start where no contact DOF pushes on its bound the reduced system is
    // singular. Start again with every contact node on the foundation,
    // where the contact forces say which nodes to release.
    clamped_start();
    _convergence->continue_solve();
    reason = run_snes();
    count_iterations(reason);
  }
  if (reason < 0)
    throw SolverError(solver_name() + " did not converge: "
                      + (_convergence->cycling ? "its Newton steps cycle between sets of contact states"
                                               : SNESConvergedReasons[reason])
                      + (_J and reason != SNES_DIVERGED_LINEAR_SOLVE ? no_equilibrium : ""));
  check_petsc(VecScale(_y, scale), "contact solver: VecScale");
}

void VariationalInequality::continue_from(VariationalInequality& earlier)
{
  newton_iterations = earlier.newton_iterations;
  linear_iterations = earlier.linear_iterations;
  _convergence->active_set_changes = earlier._convergence->active_set_changes;
  _convergence->on_newton_step = std::move(earlier._convergence->on_newton_step);
}

void VariationalInequality::set_friction(std::vector<FrictionalConstraint> friction)
{
  _p.friction = std::move(friction);
  _jacobian_weights.clear(); // its bounds changed: J is built anew
}

void VariationalInequality::record_clamped_states()
{
  std::vector<char>& closed = _closed_when_clamped;
  closed.clear();
  if (!_J)
    return;
  _elastic_known = false;
  check_petsc(elastic_residual(_y), "contact solver: K y - b");
  auto record = [&](const FrictionPoint& at, PetscScalar*)
  {
    for (const FrictionalConstraint& f : _p.friction)
      closed.push_back(friction_term(f, at).closed);
    return PetscErrorCode(0);
  };
  check_petsc(with_friction_point(_y, _elastic, record), "contact solver: the clamped states");
}

bool VariationalInequality::try_solve(double scale, int newton_steps)
{
  PetscInt max_it = 0, max_f = 0;
  PetscReal atol = 0, rtol = 0, stol = 0;
  check_petsc(SNESGetTolerances(_snes, &atol, &rtol, &stol, &max_it, &max_f), "contact solver: SNESGetTolerances");
  check_petsc(SNESSetTolerances(_snes, PETSC_DEFAULT, PETSC_DEFAULT, PETSC_DEFAULT, newton_steps, PETSC_DEFAULT),
              "contact solver: SNESSetTolerances");
  std::optional<KrylovOnReuse> krylov;
  if (_reuse_factorization)
    krylov.emplace(_snes, _reuse_options);
  const SNESConvergedReason reason = first_attempt(scale);
  check_petsc(SNESSetTolerances(_snes, PETSC_DEFAULT, PETSC_DEFAULT, PETSC_DEFAULT, max_it, PETSC_DEFAULT),
              "contact solver: SNESSetTolerances");
  if (reason < 0)
    return false;
  check_petsc(VecScale(_y, scale), "contact solver: VecScale");
  return true;
}

/// One SNES solve from y, in units of `scale` (SNESVI decides "on the
/// bound" with an absolute tolerance, 1e-8, so it works on y / s; the
/// residual K (y/s) - b/s has the same Jacobian K).
SNESConvergedReason VariationalInequality::first_attempt(double scale)
{
  _scale = scale;
  _reusing = _reuse_factorization;
  check_petsc(VecScale(_b, 1.0 / scale), "contact solver: VecScale");
  check_petsc(VecScale(_y, 1.0 / scale), "contact solver: VecScale");
  if (_balanced)
    _balanced->pose(_p.K, _J ? _J : _p.K, _b);
  set_bounds(scale);
  set_tolerances();
  if (_J) // the stiffness that turns a slip increment into a trial force
    check_petsc(MatGetDiagonal(_p.K, _stiffness), "friction: the diagonal of the contact matrix");
  const SNESConvergedReason reason = run_snes();
  count_iterations(reason);
  return reason;
}

/// sign y[dof] <= gap: y[dof] <= gap or y[dof] >= -gap, in units of the
/// scale; a pinned position on both bounds (closed) or on none (open).
void VariationalInequality::set_bounds(double scale)
{
  PetscScalar *lo, *up;
  check_petsc(VecGetArray(_lower, &lo), "contact solver: VecGetArray");
  check_petsc(VecGetArray(_upper, &up), "contact solver: VecGetArray");
  for (std::size_t k = 0; k < _p.bounded.size(); ++k)
  {
    const double bound = _p.sign[k] * _p.gap[k] / scale;
    const int pin = _pins.empty() ? 0 : _pins[k];
    lo[_p.bounded[k]] = pin > 0 or (pin == 0 and _p.sign[k] < 0) ? bound : PETSC_NINFINITY;
    up[_p.bounded[k]] = pin > 0 or (pin == 0 and _p.sign[k] > 0) ? bound : PETSC_INFINITY;
  }
  check_petsc(VecRestoreArray(_lower, &lo), "contact solver: VecRestoreArray");
  check_petsc(VecRestoreArray(_upper, &up), "contact solver: VecRestoreArray");
}

/// The absolute tolerance relative to the load unless -snes_atol is given:
/// scale-free; and the separate rows' by their own load.
void VariationalInequality::set_tolerances()
{
  PetscBool atol_given = PETSC_FALSE;
  check_petsc(PetscOptionsHasName(nullptr, _p.prefix.c_str(), "-snes_atol", &atol_given), "contact solver: PetscOptionsHasName");
  if (!atol_given)
  {
    PetscReal bnorm = 0;
    check_petsc(VecNorm(tested_load(), NORM_2, &bnorm), "contact solver: VecNorm");
    // With friction the residual decides the last step (F is not
    // linear): tighter, Newton's last steps are quadratic.
    const double relative = _J ? 1e-12 : 1e-10;
    check_petsc(SNESSetTolerances(_snes, std::max(relative * bnorm, 1e-300), PETSC_DEFAULT, PETSC_DEFAULT, PETSC_DEFAULT,
                      PETSC_DEFAULT), "contact solver: SNESSetTolerances");
  }
  _convergence->pose();
}

/// Every attempt's steps count, a failed Krylov solve's iterations too
/// (SNES leaves them out of its own count): they cost their time.
void VariationalInequality::count_iterations(SNESConvergedReason reason)
{
  PetscInt its = 0, lits = 0, failed = 0;
  check_petsc(SNESGetIterationNumber(_snes, &its), "contact solver: SNESGetIterationNumber");
  check_petsc(SNESGetLinearSolveIterations(_snes, &lits), "contact solver: SNESGetLinearSolveIterations");
  if (reason == SNES_DIVERGED_LINEAR_SOLVE)
  {
    KSP ksp;
    check_petsc(SNESGetKSP(_snes, &ksp), "contact solver: SNESGetKSP");
    check_petsc(KSPGetIterationNumber(ksp, &failed), "contact solver: KSPGetIterationNumber");
  }
  newton_iterations += its;
  linear_iterations += lits + failed;
}

SNESConvergedReason VariationalInequality::run_snes()
{
  std::optional<SolverStage::Guard> stage;
  if (_stage)
    stage.emplace(*_stage);
  _elastic_known = false; // b, K and the scale are the solve's own
  // A zero pivot in the factorisation of a Newton step's reduced system:
  // the system is singular (a body that the contact alone holds, from a
  // start that presses on nothing), a failed step as DIVERGED_DTOL is
  // (convergence.cpp), which the clamped start answers.
  SNESConvergedReason reason = SNES_DIVERGED_LINEAR_SOLVE;
  SolveOutcome o;
  const MPI_Comm comm = PetscObjectComm(reinterpret_cast<PetscObject>(_snes)); // one path on every rank
  if (const PetscErrorCode ierr = agreed_code(SNESSolve(_snes, nullptr, _y), comm); ierr == 0)
    check_petsc(SNESGetConvergedReason(_snes, &reason), "contact solver: SNESGetConvergedReason");
  else if (ierr != PETSC_ERR_MAT_LU_ZRPVT and ierr != PETSC_ERR_MAT_CH_ZRPVT)
    o.failure = solver_name() + " failed: " + petsc_error_text(ierr);
  o.reason = reason;
  if (_p.shared != MPI_COMM_NULL)
    o = shared_outcome(o, _y, _p.shared);
  if (!o.failure.empty())
    throw SolverError(o.failure);
  return static_cast<SNESConvergedReason>(o.reason);
}

SNESConvergedReason VariationalInequality::refactorised()
{
  // GMRES did not converge on an earlier factorisation: on from the last
  // iterate with J factorised whenever it changes.
  _reusing = false;
  check_petsc(SNESSetLagPreconditioner(_snes, -2), "contact solver: SNESSetLagPreconditioner");
  const SNESConvergedReason reason = run_snes();
  count_iterations(reason);
  return reason;
}

void VariationalInequality::clamped_start()
{
  // Every bounded DOF on its bound and, with friction, every frictional
  // constraint stuck (its tangential unknowns at the step's start); the
  // other DOFs (none when condensed) solve their equations: A y = b/s with
  // the clamped rows and columns eliminated and the known values moved to
  // the right-hand side. Tangential unknowns left free would slide the
  // faces as if frictionless, a start from which every pair looks slipping
  // (theory.md, "Friction").
  PetscInt start = 0;
  check_petsc(VecGetOwnershipRange(_y, &start, nullptr), "contact solver: VecGetOwnershipRange");
  std::vector<PetscInt> rows;
  const PetscScalar *lo, *up;
  check_petsc(VecGetArrayRead(_lower, &lo), "contact solver: VecGetArrayRead");
  check_petsc(VecGetArrayRead(_upper, &up), "contact solver: VecGetArrayRead");
  PetscScalar* y;
  check_petsc(VecGetArray(_y, &y), "contact solver: VecGetArray");
  for (std::size_t k = 0; k < _p.bounded.size(); ++k)
  {
    const std::int32_t dof = _p.bounded[k];
    rows.push_back(start + dof);
    y[dof] = _p.sign[k] > 0 ? up[dof] : lo[dof];
  }
  if (_J)
  {
    const PetscScalar* reference;
    check_petsc(VecGetArrayRead(_y_reference, &reference), "contact solver: VecGetArrayRead");
    for (const FrictionalConstraint& f : _p.friction)
      for (int q = 0; q < _p.tangents; ++q)
      {
        rows.push_back(start + f.tangential[q]);
        y[f.tangential[q]] = reference[f.tangential[q]] / _scale;
      }
    check_petsc(VecRestoreArrayRead(_y_reference, &reference), "contact solver: VecRestoreArrayRead");
  }
  check_petsc(VecRestoreArray(_y, &y), "contact solver: VecRestoreArray");
  check_petsc(VecRestoreArrayRead(_lower, &lo), "contact solver: VecRestoreArrayRead");
  check_petsc(VecRestoreArrayRead(_upper, &up), "contact solver: VecRestoreArrayRead");
  if (_whole)
    solve_clamped(*_whole, _b, _y, rows);
  record_clamped_states();
}

// F(y) = K y - b/s: the gradient of the quadratic energy, in units of s;
// with friction its frictional constraints' tangential rows carry the
// return map (friction.h); W F with balanced rows.
PetscErrorCode VariationalInequality::residual(SNES, Vec y, Vec F, void* context)
{
  auto* self = static_cast<VariationalInequality*>(context);
  PetscCall(self->elastic_residual(y));
  PetscCall(VecCopy(self->_elastic, F));
  if (self->_J)
    PetscCall(self->add_friction(y, F));
  if (self->_balanced)
    PetscCall(VecPointwiseMult(F, F, self->_balanced->weights()));
  return 0;
}

// The Jacobian is the constant matrix K (A, or H formed once per A); with
// friction the generalised Jacobian of its rows (friction_jacobian), built
// anew, and its factorisation with it, only when its rows' weights changed
// (on every rank alike: the factorisation is collective). The iterative
// path's preconditioner is built from P and the inactive set alone
// (inactive_set_preconditioner.h), not from J.
PetscErrorCode VariationalInequality::jacobian(SNES snes, Vec y, Mat, Mat, void* context)
{
  auto* self = static_cast<VariationalInequality*>(context);
  if (!self->_J)
    return 0;
  PetscCall(self->elastic_residual(y));
  auto build = [&](const FrictionPoint& at, PetscScalar*) -> PetscErrorCode
  {
    std::vector<double> weights = jacobian_weights(self->_p.friction, at);
    int same = weights == self->_jacobian_weights;
    PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, &same, 1, MPI_INT, MPI_LAND, self->_p.comm));
    if (same)
      return 0;
    PetscCall(friction_jacobian(self->_p.friction, at, self->_p.K, self->_J));
    self->_jacobian_weights = std::move(weights);
    if (self->_lag_by_default and !self->_preconditioner and !self->_reusing)
      PetscCall(SNESSetLagPreconditioner(snes, -2));
    if (self->_balanced)
      PetscCall(self->_balanced->weigh_jacobian(self->_J));
    return 0;
  };
  return self->with_friction_point(y, self->_elastic, build);
}

// SNES asks for the Jacobian at the point whose residual it evaluated
// last: K y - b is kept from there (a product with K less per Newton step,
// where the condensed K is dense: m^2 per product). Equal bit for bit or
// computed anew.
PetscErrorCode VariationalInequality::elastic_residual(Vec y)
{
  PetscBool same = PETSC_FALSE;
  if (_elastic_known)
    PetscCall(VecEqual(y, _elastic_at, &same));
  if (same)
    return 0;
  PetscCall(MatMult(_p.K, y, _elastic));
  PetscCall(VecAXPY(_elastic, -1.0, _b));
  PetscCall(VecCopy(y, _elastic_at));
  _elastic_known = true;
  return 0;
}

PetscErrorCode VariationalInequality::add_friction(Vec y, Vec F) const
{
  return with_friction_point(y, F, [&](const FrictionPoint& at, PetscScalar* R)
                             { add_friction_forces(_p.friction, at, R); return PetscErrorCode(0); });
}

} // namespace biotcontact
