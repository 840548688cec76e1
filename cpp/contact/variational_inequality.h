// The bound-constrained problem the contact poses (contact.h) and its
// solver: find y with l <= y <= u and F(y) = K y - b complementary to the
// bounds, the frictional constraints' tangential rows of F carrying the
// return map on the Coulomb disc (friction.h). PETSc's reduced-space
// active-set Newton (SNESVINEWTONRSLS) solves it, with the stopping rules
// of convergence.h. Without friction F is linear and K its exact Jacobian.
#pragma once

#include "contact/convergence.h"
#include "contact/friction.h"
#include "contact/whole_system.h"
#include "solvers/inactive_set_preconditioner.h"
#include "solvers/row_weights.h"
#include "solvers/linear_solver.h"

#include <memory>
#include <optional>
#include <petscsnes.h>
#include <string>
#include <utility>
#include <vector>

namespace biotcontact
{

/// What a friction whose Newton iteration does not settle (no linear
/// solve failed) may mean: a body that friction cannot hold, or contact
/// states that the step changes too much at once (a spreading opening:
/// docs/theory.md, "Newton on the cubic law"; a well into a closed fault,
/// whose first steps must be short: test_fault_network).
constexpr const char* no_equilibrium = " (with friction: a body that friction cannot hold has no quasi-static "
                                       "equilibrium, or the step is too long for the contact states to settle: "
                                       "time.retry halves it, time.adaptive chooses it)";

/// @brief A VI as the contact poses it: its communicator (the system's, or
/// PETSC_COMM_SELF when every rank solves the same small problem), options
/// prefix and log stage (none when empty), the prefix of the system it
/// comes from (its messages), its matrix K and a vector like y; the
/// bounded positions of y (local) with their gaps and signs,
/// sign y <= gap; the frictional constraints in y's numbering, their
/// tangents each (d - 1) and whether any rank has one; y's separate rows
/// (convergence.h); and whether K changes in a few rows between most
/// solves (the monolithic system with conduit faults: operator_nudged).
struct VIProblem
{
  MPI_Comm comm;
  std::string prefix, stage, system_prefix;
  Mat K;
  Vec layout;
  std::vector<std::int32_t> bounded;
  std::vector<double> gap, sign;
  std::vector<FrictionalConstraint> friction;
  int tangents = 0;
  bool frictional = false;
  std::vector<std::int32_t> separate_rows;
  bool changing = false;
  MPI_Comm shared = MPI_COMM_NULL; // ranks that each solve it alone: rank 0's outcome is theirs
};

/// @brief The solver of a VIProblem (SNES vinewtonrsls), options-driven.
class VariationalInequality
{
public:
  /// `whole` when the VI is posed on the whole system (nullptr when it is
  /// on a condensed one). Throws OptionsError for options that make no VI
  /// solver.
  VariationalInequality(VIProblem problem, const std::optional<WholeSystem>& whole);
  ~VariationalInequality();
  VariationalInequality(const VariationalInequality&) = delete;
  VariationalInequality& operator=(const VariationalInequality&) = delete;

  /// The load b and the unknown y (the start on entry to solve, the
  /// solution after), in the caller's units.
  Vec load() const { return _b; }
  Vec unknown() const { return _y; }
  /// The start of the step in y's numbering: friction's slip increments are
  /// measured from it (nullptr without friction).
  Vec slip_reference() const { return _y_reference; }

  /// Solves in units of `scale` (SNES decides "on a bound" with an absolute
  /// tolerance of 1e-8); retried from the clamped state when the first
  /// attempt fails. Throws SolverError when both do.
  void solve(double scale);
  /// One attempt of at most `newton_steps` Newton steps, no clamped
  /// restart: whether it converged (y is then the solution; else y and
  /// the load are spent).
  bool try_solve(double scale, int newton_steps);

  /// The bounded positions of y (local), VIProblem::bounded.
  const std::vector<std::int32_t>& bounded() const { return _p.bounded; }
  /// Per bounded position from the next solve on: 0 bounded as posed, 1
  /// pinned closed (both bounds at the gap), -1 pinned open (no bound);
  /// empty: all as posed (coupling/pins.h).
  void pin(std::vector<std::int8_t> pins) { _pins = std::move(pins); }

  /// The frictional constraints anew, in the same positions (a law
  /// changed: a bond broke, or a new step restored the step's start).
  void set_friction(std::vector<FrictionalConstraint> friction);
  /// Per frictional constraint, whether it was closed (pressed on its
  /// bound, friction_term) in the last clamped start (every bounded DOF on
  /// its bound, every frictional constraint stuck: a state that neither
  /// the path nor the laws change); empty before one or without friction.
  const std::vector<char>& closed_when_clamped() const { return _closed_when_clamped; }

  /// This solver goes on from `earlier` (another path's): the run's counts
  /// and its progress line.
  void continue_from(VariationalInequality& earlier);

  /// K was reassembled: the next Newton step factorises anew.
  void operator_changed();
  /// A few rows of K changed (a conduit fault's apertures): where an earlier
  /// factorisation is reused, it preconditions GMRES on the new K; else as
  /// operator_changed.
  void operator_nudged();
  /// Solves to `relative` (iterative): the Krylov and the Newton tolerance.
  void set_tolerance(double relative);

  /// The factorisations in the VI's own log stage (a condensed VI's; 0
  /// without a stage: the system's stage counts them).
  long factorizations() const;

  /// Whether an earlier factorisation preconditions GMRES on the next
  /// Jacobians (3D friction or a changing K in 3D, on the whole system,
  /// factorised; reuse_factorization).
  bool reuses_factorization() const { return _reuse_factorization; }
  /// Whether the VI has frictional constraints (a generalised Jacobian).
  bool frictional() const { return _J != nullptr; }

  ContactConvergence& convergence() { return *_convergence; }
  const ContactConvergence& convergence() const { return *_convergence; }
  /// Preconditioner set-ups and their seconds (iterative; -1 otherwise).
  long preconditioner_setups() const { return _preconditioner ? _preconditioner->setups : -1; }
  double preconditioner_setup_time() const { return _preconditioner ? _preconditioner->setup_time : 0; }

  long newton_iterations = 0, linear_iterations = 0;

private:
  void make_friction_operators();
  void create_snes();
  /// The preconditioner of the iterative method, then the user's options.
  void set_from_options();
  void set_bounds(double scale);
  /// The absolute tolerances from the (scaled) load.
  void set_tolerances();
  SNESConvergedReason first_attempt(double scale);
  SNESConvergedReason run_snes();
  void count_iterations(SNESConvergedReason reason);
  void clamped_start();
  /// closed_when_clamped() of the clamped state y.
  void record_clamped_states();
  /// 3D friction or a changing K in 3D on the whole system, factorised
  /// (set_from_options): the factorisation of an earlier Jacobian
  /// preconditions GMRES on the next.
  void reuse_factorization();
  /// "the contact solver (SNES <type>)": the SNES type the options made,
  /// for the solver's errors.
  std::string solver_name() const;
  /// After GMRES failed on an earlier factorisation: the solve goes on from
  /// its last iterate, the Jacobian factorised whenever it changes.
  SNESConvergedReason refactorised();
  static PetscErrorCode residual(SNES, Vec y, Vec F, void* context);
  static PetscErrorCode jacobian(SNES, Vec y, Mat, Mat, void* context);
  /// F += the friction forces at y (F holds K y - b on entry).
  PetscErrorCode add_friction(Vec y, Vec F) const;
  /// K y - b into _elastic, unless it holds that of this very y already.
  PetscErrorCode elastic_residual(Vec y);
  /// use(at, R): friction's point `at` at y with R the array of r (K y - b;
  /// writable: the forces go into it), the arrays given back after.
  template <typename Use>
  PetscErrorCode with_friction_point(Vec y, Vec r, Use use) const;
  /// The load the convergence tests measure: b, or W b with balanced rows.
  Vec tested_load() const { return _balanced ? _balanced->load() : _b; }

  VIProblem _p;
  std::optional<WholeSystem> _whole;
  double _scale = 1;
  Vec _y = nullptr, _b = nullptr, _residual = nullptr, _lower = nullptr, _upper = nullptr;
  SNES _snes = nullptr;
  std::unique_ptr<SolverStage> _stage;
  std::unique_ptr<ContactConvergence> _convergence;
  std::vector<std::int8_t> _pins; // per bounded position (pin)
  std::unique_ptr<InactiveSetPreconditioner> _preconditioner;
  bool _lag_by_default = false;
  bool _reuse_factorization = false; // reuse_factorization()
  std::vector<std::pair<std::string, std::string>> _reuse_options; // its PETSc options (name, value)
  bool _reusing = false;             // in this solve: off once refactorised()
  PetscBool _snes_rtol_given = PETSC_FALSE; // -<prefix>snes_rtol on the command line
  // Friction: the generalised Jacobian (friction.h), the start of the step
  // (unscaled), the diagonal of K (the stiffness that turns a slip
  // increment into a trial force).
  Mat _J = nullptr;
  std::vector<double> _jacobian_weights; // J's as last built (jacobian_weights); empty once K changed
  std::vector<char> _closed_when_clamped; // closed_when_clamped()
  Vec _y_reference = nullptr, _stiffness = nullptr;
  // K y - b at the y of this SNES solve's last residual (elastic_residual).
  Vec _elastic = nullptr, _elastic_at = nullptr;
  bool _elastic_known = false;
  std::unique_ptr<BalancedRows> _balanced; // the iterative coupled system's row weights
};

template <typename Use>
PetscErrorCode VariationalInequality::with_friction_point(Vec y, Vec r, Use use) const
{
  const PetscScalar *Y, *start, *c;
  PetscScalar* R;
  PetscFunctionBeginUser;
  PetscCall(VecGetArrayRead(y, &Y));
  PetscCall(VecGetArray(r, &R));
  PetscCall(VecGetArrayRead(_y_reference, &start));
  PetscCall(VecGetArrayRead(_stiffness, &c));
  PetscCall(use(FrictionPoint{Y, R, start, c, _scale, _p.tangents}, R));
  PetscCall(VecRestoreArrayRead(y, &Y));
  PetscCall(VecRestoreArray(r, &R));
  PetscCall(VecRestoreArrayRead(_y_reference, &start));
  PetscCall(VecRestoreArrayRead(_stiffness, &c));
  PetscFunctionReturn(0);
}

} // namespace biotcontact
