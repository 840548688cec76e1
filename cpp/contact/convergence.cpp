#include "contact/convergence.h"

#include "solvers/backward_error.h"
#include "solvers/solver.h"

#include <algorithm>
#include <cmath>
#include <utility>

namespace biotcontact
{

void residual_round_off(Mat K, Vec weights, Vec y, Vec b, Vec r)
{
  absolute_product(K, y, r);
  Vec magnitude;
  check_petsc(VecDuplicate(b, &magnitude), "round-off: VecDuplicate");
  if (weights)
    check_petsc(VecPointwiseMult(r, r, weights), "round-off: VecPointwiseMult");
  check_petsc(VecCopy(b, magnitude), "round-off: VecCopy");
  check_petsc(VecAbs(magnitude), "round-off: VecAbs");
  check_petsc(VecAXPY(r, 1.0, magnitude), "round-off: VecAXPY");
  check_petsc(VecScale(r, PETSC_MACHINE_EPSILON), "round-off: VecScale");
  check_petsc(VecDestroy(&magnitude), "round-off: VecDestroy");
}

ContactConvergence::ContactConvergence(MPI_Comm comm, VIBounds bounds, std::vector<std::int32_t> separate_rows)
    : _comm(comm), _bounds(bounds), _separate_rows(std::move(separate_rows))
{
  long rows = static_cast<long>(_separate_rows.size());
  MPI_Allreduce(MPI_IN_PLACE, &rows, 1, MPI_LONG, MPI_SUM, _comm);
  _any_separate = rows > 0;
}

void ContactConvergence::attach(SNES snes, Vec load, bool friction)
{
  _snes = snes, _load = load, _friction = friction;
  // SNESSetConvergenceTest's callback takes the step, ||x||, ||dx||, ||F||,
  // the reason and the context; the test reads the step and ||F||.
  auto test = [](SNES s, PetscInt iteration, PetscReal, PetscReal, PetscReal fnorm, SNESConvergedReason* reason,
                 void* context) -> PetscErrorCode
  { return static_cast<ContactConvergence*>(context)->converged(s, iteration, fnorm, reason); };
  check_petsc(SNESSetConvergenceTest(snes, test, this, nullptr), "contact solver: SNESSetConvergenceTest");
  check_petsc(SNESMonitorSet(snes, &ContactConvergence::monitor, this, nullptr), "contact solver: SNESMonitorSet");
}

void ContactConvergence::watch(KSP ksp)
{
  check_petsc(KSPMonitorSet(ksp, &ContactConvergence::stagnation, this, nullptr), "contact solver: KSPMonitorSet");
}

void ContactConvergence::pose()
{
  // With friction the residual decides the last step (F is not linear):
  // tighter, as the forces' absolute tolerance (ContactSolver::pose).
  double load = 0;
  check_petsc(separate_norm(_load, &load), "contact solver: the load of the separate rows");
  _separate_tolerance = (_friction ? 1e-12 : 1e-10) * load;
}

PetscErrorCode ContactConvergence::active_contact_dofs(Vec x, std::vector<char>* active, bool* clipped) const
{
  // PETSc's rule (SNESVIGetActiveSetIS): a DOF is active when it lies on a
  // bound to 1e-8 and F pushes it against that bound. A DOF on a bound
  // that F does not push was put there by the projection after a step that
  // left it free (`clipped`): that step did not solve its equation.
  Vec F = nullptr;
  PetscCall(SNESGetFunction(_snes, &F, nullptr, nullptr));
  const PetscScalar *X, *R, *lo, *up;
  PetscCall(VecGetArrayRead(x, &X));
  PetscCall(VecGetArrayRead(F, &R));
  PetscCall(VecGetArrayRead(_bounds.lower, &lo));
  PetscCall(VecGetArrayRead(_bounds.upper, &up));
  active->assign(_bounds.bounded.size(), 0);
  for (std::size_t k = 0; k < _bounds.bounded.size(); ++k)
  {
    const std::int32_t i = _bounds.bounded[k];
    const bool on_lower = X[i] <= lo[i] + 1e-8, on_upper = X[i] >= up[i] - 1e-8;
    (*active)[k] = (on_lower and R[i] > 0) or (on_upper and R[i] < 0);
    if (clipped)
      *clipped = *clipped or ((on_lower or on_upper) and !(*active)[k]);
  }
  PetscCall(VecRestoreArrayRead(x, &X));
  PetscCall(VecRestoreArrayRead(F, &R));
  PetscCall(VecRestoreArrayRead(_bounds.lower, &lo));
  PetscCall(VecRestoreArrayRead(_bounds.upper, &up));
  return 0;
}

PetscErrorCode ContactConvergence::monitor(SNES snes, PetscInt iteration, PetscReal, void* context)
{
  auto* self = static_cast<ContactConvergence*>(context);
  if (iteration > 0)
  {
    // The set recorded before this step was the one the step used.
    int changed = self->_any_used and self->_pending != self->_used, any = 0;
    MPI_Allreduce(&changed, &any, 1, MPI_INT, MPI_MAX, self->_comm);
    self->active_set_changes += any;
    self->_used = self->_pending;
    self->_any_used = true;
  }
  Vec x = nullptr;
  PetscCall(SNESGetSolution(snes, &x));
  bool clipped = false;
  PetscCall(self->active_contact_dofs(x, &self->_pending, &clipped));
  if (iteration > 0)
  {
    int differs = self->_pending != self->_used or clipped, any = 0;
    MPI_Allreduce(&differs, &any, 1, MPI_INT, MPI_MAX, self->_comm);
    self->_set_repeated = !any;
    if (self->on_newton_step)
      self->on_newton_step(static_cast<int>(iteration));
  }
  return 0;
}

PetscErrorCode ContactConvergence::stagnation(KSP ksp, PetscInt iteration, PetscReal rnorm, void* context)
{
  // A Newton step whose reduced system is singular (a body held in the
  // normal direction by one or two active nodes, see ContactSolver::solve),
  // or whose right-hand side is round-off (the forced first step of a solve
  // that starts converged), makes the Krylov method stagnate. A converging
  // step takes tens of iterations (docs/performance.md); one that has not
  // reduced its residual by 1% over the last `stagnation_window` is stopped
  // (its iteration limit lowered to now: DIVERGED_ITS), and the solve
  // restarts from the clamped state. The limit is restored at the next
  // solve.
  auto* self = static_cast<ContactConvergence*>(context);
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

PetscErrorCode ContactConvergence::start(SNES snes, PetscReal fnorm, PetscReal rtol)
{
  PetscFunctionBeginUser;
  // With friction F is not linear, and a start far off (the clamped start
  // of a body that slides) would make any residual "relative": relative to
  // the load then, where that is smaller.
  PetscReal load = 0;
  PetscCall(VecNorm(_load, NORM_2, &load));
  _relative_target = rtol * std::min(fnorm, _friction ? load : fnorm);
  _round_off_bound = round_off_ceiling * load;
  _repeated_set_bound = repeated_set_fraction * std::max(fnorm, load);
  _divergence_bound = divergence_ratio * std::max(fnorm, load);
  // The active set method's rule trusts a step to solve its set: a
  // factorisation's, or a Krylov solve as tight as rtol (the project ties
  // the two); with a looser -<prefix>ksp_rtol (0.5 on hertz: the set
  // repeated at 4e-4 of the first residual, the contact pressure 6 % off,
  // exit 0) the residual tests decide.
  KSP ksp = nullptr;
  PetscCall(SNESGetKSP(snes, &ksp));
  PetscBool preonly = PETSC_FALSE;
  PetscCall(PetscObjectTypeCompare(reinterpret_cast<PetscObject>(ksp), KSPPREONLY, &preonly));
  PetscReal krylov_rtol = 0;
  PetscCall(KSPGetTolerances(ksp, &krylov_rtol, nullptr, nullptr, nullptr));
  _steps_exact = preonly or krylov_rtol <= rtol;
  Vec F = nullptr;
  PetscCall(SNESGetFunction(snes, &F, nullptr, nullptr));
  double norm = 0;
  PetscCall(separate_norm(F, &norm));
  _separate_relative_target = rtol * norm;
  _separate_met = false;
  PetscFunctionReturn(0);
}

PetscErrorCode ContactConvergence::converged(SNES snes, PetscInt iteration, PetscReal fnorm, SNESConvergedReason* reason)
{
  PetscReal atol = 0, rtol = 0, stol = 0;
  PetscInt max_it = 0, max_f = 0;
  PetscCall(SNESGetTolerances(snes, &atol, &rtol, &stol, &max_it, &max_f));
  // PETSc's test for the VI methods (vi.c, SNESConvergedDefault_VI), with
  // at least one step taken (SNESSetForceIteration) ...
  *reason = SNES_CONVERGED_ITERATING;
  // With friction the clamped start continues the solve whose first
  // attempt failed, with that attempt's targets: from the clamped start's
  // own residual (on a fine fracture network 2.5e-11 of the load, every
  // pair stuck as in the solution) rtol would ask for less than the
  // residual's round-off. Frictionless, F is linear and the repeated
  // active set ends the solve at round-off.
  if (iteration == 0)
  {
    _continued = std::exchange(_continuing, false) and _friction;
    _attempt = _continued ? std::move(_norms) : std::vector<PetscReal>{};
    _attempt_cycled = _continued and cycling;
    _norms.clear(), cycling = false;
    if (!_continued)
      PetscCall(start(snes, fnorm, rtol));
  }
  double forces = 0, separate_part = 0;
  PetscCall(split_norm(fnorm, &forces, &separate_part));
  bool solved = false;
  PetscCall(separate_solved(iteration, separate_part, &solved));
  const bool separate = separate_may_stop(solved);
  if (PetscIsInfOrNanReal(fnorm))
    *reason = SNES_DIVERGED_FNORM_NAN;
  else if ((iteration > 0 or _friction) and forces < atol and separate)
    *reason = SNES_CONVERGED_FNORM_ABS; // a step taken, or the start with friction
  else if (iteration > 0 and forces < _relative_target and separate)
    *reason = SNES_CONVERGED_FNORM_RELATIVE;
  // With friction the residual's round-off (each force row's eps sum_j
  // |K_ij y_j|, stiff rows of small cells) can lie above atol and a
  // coupling iteration's relative target: on a fine fracture network the
  // Newton steps jittered at 5e-12 of the load until the line search
  // failed. A residual within it is solved, if below round_off_ceiling of
  // the load.
  else if (_friction and iteration > 0 and separate and forces < _round_off_bound)
  {
    bool within = false;
    PetscCall(at_round_off(forces, &within));
    if (within)
      *reason = SNES_CONVERGED_FNORM_ABS;
  }
  // ... and the stopping rule of the primal-dual active set method: the
  // step solved F = 0 on the inactive set, and the active set at its result
  // is the one it used, so no DOF crosses its bound and every contact force
  // pushes the right way: x solves the VI (to the linear solver's
  // tolerance). F is linear, so this is the solution on that set even where
  // the residual's round-off (A x and b of very different sizes, pressures
  // in units of the displacement scale on the coupled system) lies above
  // atol, which the test above would never see met. SNES has no reason for
  // it; CONVERGED_ITS stands for "stopped by the method's own rule".
  // With friction F is not linear: only the residual says when it is
  // solved.
  // A step that left the residual above a fraction of the first one (or of
  // the load, where the start was close) did not solve F = 0 on its set: a
  // singular reduced system (a body held by the contact alone, from a start
  // that presses on nothing) solved by a factorisation that did not see
  // it. Above both it is refused at once (the solver starts again
  // clamped), else iterated on.
  else if (iteration > 0 and _set_repeated and !_friction and _steps_exact)
  {
    if (fnorm <= _repeated_set_bound)
      *reason = SNES_CONVERGED_ITS;
    else if (fnorm > _repeated_set_bound / repeated_set_fraction)
      *reason = SNES_DIVERGED_DTOL;
  }
  if (_friction and *reason == SNES_CONVERGED_ITERATING)
    *reason = newton_path(fnorm);
  return 0;
}

SNESConvergedReason ContactConvergence::newton_path(PetscReal fnorm)
{
  _norms.push_back(fnorm);
  // A semismooth Newton step is exact on its contact states: states each
  // of whose steps lands in the next repeat the same iterates, and their
  // residuals, to the last digits (friction's kink at a pair with t_N = 0:
  // Phan's crack loaded at once on the coupled system, two states; its
  // cohesive crack opening along its whole length, four).
  if (newton_cycle(_norms, cycle_periods))
  {
    cycling = true;
    return SNES_DIVERGED_DTOL;
  }
  // test_fault_network's star fed by a well of 1e-2 m^2/s at dt = 1 s: the
  // clamped start's residual reached 1e22 from 1e7 and wandered for 100
  // steps, each a factorisation.
  if (fnorm > _divergence_bound)
    return SNES_DIVERGED_DTOL;
  // A first attempt whose line search shrinks every step to nothing (the
  // 50-fracture network's initial equilibrium on 2 ranks crept by 0.1-1 %
  // a step for 30 steps from 3e9 N, where one rank's search failed at the
  // third) ends, and the clamped start, whose pairs all stick, goes on.
  if (!_continued and newton_stall(_norms, stall_steps))
    return SNES_DIVERGED_DTOL;
  // A clamped start whose first step lands where the first attempt's did
  // retraces that attempt (the step depends on its iterate alone), whose
  // verdict stands: found no other path (the onset of test_cohesive_opening
  // on the coupled system: 24 more factorisations of the attempt's states).
  if (_continued and rejoins_attempt(_norms, _attempt))
  {
    cycling = _attempt_cycled;
    return SNES_DIVERGED_DTOL;
  }
  return SNES_CONVERGED_ITERATING;
}

namespace
{
/// Two residual norms equal to 1e-9 (the last digits of a repeated iterate).
bool same_norm(double a, double b) { return std::abs(a - b) <= 1e-9 * std::max(a, b); }
} // namespace

bool rejoins_attempt(std::span<const double> norms, std::span<const double> attempt)
{
  return norms.size() == 2 and attempt.size() >= 2 and same_norm(norms[1], attempt[1]);
}

bool newton_stall(std::span<const double> norms, std::size_t steps)
{
  const std::size_t n = norms.size();
  if (steps == 0 or n < steps + 1)
    return false;
  for (std::size_t k = n - steps; k < n; ++k)
    if (!(norms[k] > (1 - stall_reduction) * norms[k - 1]))
      return false;
  return true;
}

bool newton_cycle(std::span<const double> norms, std::size_t periods)
{
  const std::size_t n = norms.size();
  for (std::size_t length = 2; length <= longest_newton_cycle and periods >= 1 and n >= length * periods; ++length)
  {
    bool repeats = true, varies = false;
    for (std::size_t k = n - length * periods; k < n; ++k)
    {
      repeats = repeats and (k < n - length * (periods - 1) or same_norm(norms[k], norms[k - length]));
      varies = varies or (k > n - length * periods and !same_norm(norms[k], norms[k - 1]));
    }
    if (repeats and varies)
      return true;
  }
  return false;
}

PetscErrorCode ContactConvergence::round_off_norms(double* forces, double* separate) const
{
  PetscFunctionBeginUser;
  Vec y = nullptr, r = nullptr;
  PetscCall(SNESGetSolution(_snes, &y));
  PetscCall(VecDuplicate(y, &r));
  residual_round_off(_operator, _weights, y, _load, r);
  PetscReal total = 0;
  PetscCall(VecNorm(r, NORM_2, &total));
  PetscCall(separate_norm(r, separate));
  PetscCall(VecDestroy(&r));
  *forces = std::sqrt(std::max(total * total - *separate * *separate, 0.0));
  PetscFunctionReturn(0);
}

PetscErrorCode ContactConvergence::at_round_off(PetscReal fnorm, bool* within) const
{
  PetscFunctionBeginUser;
  *within = false;
  if (!_operator)
    PetscFunctionReturn(0);
  double forces = 0, separate = 0;
  PetscCall(round_off_norms(&forces, &separate));
  *within = fnorm <= forces;
  PetscFunctionReturn(0);
}

PetscErrorCode ContactConvergence::separate_norm(Vec v, double* norm) const
{
  const double* V = nullptr;
  double sum = 0;
  PetscCall(VecGetArrayRead(v, &V));
  for (std::int32_t i : _separate_rows)
    sum += V[i] * V[i];
  PetscCall(VecRestoreArrayRead(v, &V));
  MPI_Allreduce(MPI_IN_PLACE, &sum, 1, MPI_DOUBLE, MPI_SUM, _comm);
  *norm = std::sqrt(sum);
  return 0;
}

PetscErrorCode ContactConvergence::split_norm(PetscReal fnorm, double* forces, double* separate) const
{
  // The tests in N (atol, the relative target, the round-off) are the
  // force rows': SNES's fnorm holds the separate rows too, whose own
  // round-off can lie above atol (network3d's monolithic step at 0.5 m^3/s:
  // the forces at 0.4 N, the mass balances at 61 against their round-off
  // 257 and atol 53, for 100 Newton steps).
  Vec F = nullptr;
  PetscCall(SNESGetFunction(_snes, &F, nullptr, nullptr));
  PetscCall(separate_norm(F, separate));
  *forces = std::sqrt(std::max(fnorm * fnorm - *separate * *separate, 0.0));
  return 0;
}

PetscErrorCode ContactConvergence::separate_solved(PetscInt iteration, double norm, bool* solved)
{
  *solved = norm <= _separate_tolerance or (iteration > 0 and norm <= _separate_relative_target);
  // With friction their tolerances can lie below their own round-off: the
  // undrained first step of a conduit in an impermeable rock has a load of
  // 2e-7 m^2/s on them (tolerance 2e-19) against exchanges of 1e-3 that
  // cancel, the residual 1.4e-14 and its round-off 5.7e-14, where the
  // Newton steps jittered to their limit. A residual within it is solved.
  if (!*solved and _friction and iteration > 0 and _operator)
  {
    double forces = 0, separate = 0;
    PetscCall(round_off_norms(&forces, &separate));
    *solved = norm <= separate;
  }
  return 0;
}

bool ContactConvergence::separate_may_stop(bool met)
{
  // With friction the residual alone decides the last step, and a separate
  // row's tolerance lies far above its round-off where its load holds terms
  // that cancel at the solution (a fault's ends held at p_D: T_e p_D, 1e-3
  // m^3/s, against flows of 1e-10 m^3/s), an error that the step length
  // turns into volume (1e-9 m^3 per step of 1e6 s on the 3D box). One more
  // Newton step once met takes them to round-off.
  if (!met or !(_friction and _any_separate))
    return met;
  return std::exchange(_separate_met, true);
}

} // namespace biotcontact
