// The stopping rules of the contact VI's Newton iteration (SNES
// vinewtonrsls): PETSc's residual test, the primal-dual active set rule
// "the step kept its active set", a separate test for rows in other units
// than the forces, and the Krylov stagnation of a singular reduced system.
#pragma once

#include <cstdint>
#include <functional>
#include <mpi.h>
#include <petscsnes.h>
#include <span>
#include <vector>

namespace biotcontact
{

/// The stopping rule of a repeated active set holds where the step has
/// brought the residual below this fraction of the larger of the solve's
/// first and the load.
constexpr double repeated_set_fraction = 1e-3;

/// With friction a residual at its round-off (residual_round_off) ends the
/// solve where it lies below this fraction of the load.
constexpr double round_off_ceiling = 1e-8;

/// With friction, a Newton step that lifts the residual above this multiple
/// of the larger of the solve's first residual and the load has met a
/// singular reduced system (a piece the open pairs leave free): its steps
/// wander without bound, and the solve ends.
constexpr double divergence_ratio = 1e6;

/// With friction, a solve whose residuals repeat a cycle of at most
/// longest_newton_cycle values for cycle_periods periods cycles between sets of
/// contact states (network3d's monolithic step at 0.5 m^3/s: nine values).
constexpr std::size_t cycle_periods = 3;
constexpr std::size_t longest_newton_cycle = 12;

/// With friction, a first attempt whose last stall_steps Newton steps each
/// reduced the residual by less than stall_reduction of it has stalled:
/// its line search finds no descent along the semismooth direction, and
/// the clamped start follows (convergence.cpp).
constexpr std::size_t stall_steps = 3;
constexpr double stall_reduction = 1e-3;

/// Whether each of the last `steps` steps of `norms` reduced the norm by
/// less than stall_reduction of it.
bool newton_stall(std::span<const double> norms, std::size_t steps);

/// Whether a clamped start's residuals `norms` (its start, then its first
/// step) rejoin those of the first attempt it follows, `attempt`: its first
/// step's residual equals the attempt's first step's to 1e-9.
bool rejoins_attempt(std::span<const double> norms, std::span<const double> attempt);

/// Whether the last `periods` periods of `norms` repeat a cycle of L
/// values for some L from 2 to longest_newton_cycle: each equal to the one L
/// before it to 1e-9, and not all the same (stagnation is no cycle).
bool newton_cycle(std::span<const double> norms, std::size_t periods);

/// r = eps (W |K| |y| + |b|): a bound of the round-off of each entry of
/// W (K y - b) (eps the machine's; W the row weights, nullptr for none;
/// collective).
void residual_round_off(Mat K, Vec weights, Vec y, Vec b, Vec r);

/// @brief The bounds of a VI's unknown: its lower and upper bound vectors,
/// and the positions (local, in its numbering) that carry a bound.
struct VIBounds
{
  Vec lower, upper;
  std::span<const std::int32_t> bounded;
};

/// @brief When a Newton iteration of the contact VI F(x) = K x - b (+ the
/// friction forces) complementary to the bounds has converged, as SNES's
/// monitor, convergence test and (iterative) Krylov monitor.
///
/// The residual's norm is the forces' (N): SNES's norm less the rows in
/// other units (the mass balances of the monolithic system, m^3/s), the
/// `separate_rows`, whose residual is judged against their own load.
class ContactConvergence
{
public:
  /// A Krylov solve of a Newton step that reduces its residual by less
  /// than 1% over this many iterations has stagnated (stagnation).
  static constexpr PetscInt stagnation_window = 50;

  /// `comm` is the VI's; `separate_rows` local rows of its unknown.
  ContactConvergence(MPI_Comm comm, VIBounds bounds, std::vector<std::int32_t> separate_rows);

  /// Whether any rank has separate rows (collective, at construction).
  bool has_separate_rows() const { return _any_separate; }

  /// Tests `snes`'s steps, with `load` the VI's b (as posed); `friction`:
  /// F is not linear.
  void attach(SNES snes, Vec load, bool friction);
  /// Stops a Krylov solve of a Newton step that stagnates.
  void watch(KSP ksp);
  /// The load has been posed: the separate rows' tolerance from it.
  void pose();
  /// With friction, a residual at the round-off of K y - b (weighted by
  /// `weights`, nullptr for none) ends the solve (convergence.cpp).
  void measure_round_off(Mat K, Vec weights) { _operator = K, _weights = weights; }
  /// The next SNES solve continues the last one (the clamped start after
  /// a failed first attempt): with friction it keeps that one's targets.
  void continue_solve() { _continuing = true; }

  /// The bounded DOFs that are active at x by PETSc's rule
  /// (SNESVIGetActiveSetIS), into `active`; `clipped` tells of a DOF on a
  /// bound that F does not push. Returns PETSc's error code: it runs inside
  /// SNES's monitor.
  PetscErrorCode active_contact_dofs(Vec x, std::vector<char>* active, bool* clipped = nullptr) const;

  /// Newton steps whose inactive set differed from the previous step's
  /// (across solves): each may cost one factorisation.
  long active_set_changes = 0;
  /// Called after each Newton step with its number.
  std::function<void(int)> on_newton_step;
  /// With friction, the last solve was stopped because its residuals
  /// repeated a cycle for cycle_periods periods (newton_cycle;
  /// its reason DIVERGED_DTOL).
  bool cycling = false;

private:
  /// A solve's first residual `fnorm` sets its relative targets (rtol
  /// times it, or the load's with friction where that is smaller).
  PetscErrorCode start(SNES snes, PetscReal fnorm, PetscReal rtol);
  /// The norm of v on the separate rows, into `norm` (collective).
  PetscErrorCode separate_norm(Vec v, double* norm) const;
  /// SNES's residual norm `fnorm` split into the force rows' and the
  /// separate rows' (collective).
  PetscErrorCode split_norm(PetscReal fnorm, double* forces, double* separate) const;
  /// Whether the residual, of norm `norm` on the separate rows, is small
  /// there, into `solved`: below their tolerances or, with friction,
  /// within their round-off (collective; from the convergence test).
  PetscErrorCode separate_solved(PetscInt iteration, double norm, bool* solved);
  /// Whether a solve whose separate rows are solved (`met`) may stop.
  bool separate_may_stop(bool met);
  /// The norms of residual_round_off at the current unknown on the force
  /// rows and on the separate rows (collective).
  PetscErrorCode round_off_norms(double* forces, double* separate) const;
  /// Whether the residual's norm `fnorm` on the force rows lies within
  /// the round-off of the solve's operator at its current unknown, into
  /// `within` (collective).
  PetscErrorCode at_round_off(PetscReal fnorm, bool* within) const;
  /// Before each Newton step (and after the last): records the active set
  /// the next step will use, and counts changes.
  static PetscErrorCode monitor(SNES, PetscInt iteration, PetscReal, void* context);
  /// PETSc's convergence test of the VI methods and the active set rule
  /// (convergence.cpp), at Newton step `iteration` with residual norm
  /// `fnorm` (SNESSetConvergenceTest's callback, attach(), forwards to it).
  PetscErrorCode converged(SNES snes, PetscInt iteration, PetscReal fnorm, SNESConvergedReason* reason);
  /// With friction, after a step that met no test with residual norm
  /// `fnorm`: DIVERGED_DTOL where the solve cycles (newton_cycle) or its
  /// first attempt stalls (newton_stall), else CONVERGED_ITERATING.
  SNESConvergedReason newton_path(PetscReal fnorm);
  static PetscErrorCode stagnation(KSP, PetscInt iteration, PetscReal rnorm, void* context);

  MPI_Comm _comm;
  VIBounds _bounds;
  std::vector<std::int32_t> _separate_rows;
  bool _any_separate = false;
  SNES _snes = nullptr;
  Vec _load = nullptr;
  bool _friction = false;
  bool _continuing = false; // continue_solve() until the next first test
  bool _continued = false;  // the current solve continues a failed attempt
  Mat _operator = nullptr;  // measure_round_off
  Vec _weights = nullptr;
  std::vector<char> _pending, _used; // active flags of the bounded DOFs
  bool _any_used = false;
  bool _set_repeated = false;        // the last step's result keeps the set it used
  bool _steps_exact = true;          // a step solves its set: a factorisation, or Krylov to rtol (start)
  PetscReal _relative_target = 0;    // rtol times the first residual of a solve
  PetscReal _repeated_set_bound = 0; // a fraction of it or of the load (converged)
  PetscReal _round_off_bound = 0;    // round_off_ceiling times the load
  PetscReal _divergence_bound = 0;   // divergence_ratio times the first or the load
  // The residual on the separate rows is small below the larger of these:
  // their load's times the relative tolerance (pose), and rtol times the
  // solve's first.
  PetscReal _separate_tolerance = 0, _separate_relative_target = 0;
  bool _separate_met = false; // this solve's separate rows met their tolerance once
  std::vector<PetscReal> _residuals; // of the current Krylov solve (stagnation)
  std::vector<PetscReal> _norms;     // of the current Newton solve (newton_cycle)
  std::vector<PetscReal> _attempt;   // the failed first attempt's, in a clamped start
  bool _attempt_cycled = false;      // whether it ended in a cycle
  PetscInt _lowered_from = 0;        // the iteration limit before a stagnated solve lowered it
};

} // namespace biotcontact
