// Signorini contact against rigid foundations of any normal nu_F and
// between a fault's faces (alg. "Mechanics with frictionless Signorini
// contact"; friction: contact_law.h).
//
// The energy is quadratic, so with A the matrix of the (mechanics or
// monolithic) system and b its load vector the variational inequality is the
// bound-constrained problem
//     find x' with l <= x' <= g and F(x') = A' x' - b' complementary to the
//     bounds,
// in the variables x' = T x of change_of_variables.h, where each constraint
// u.nu_F <= g_a of a contact node is a bound on one DOF (T = I, A' = A
// when every normal is a coordinate axis). PETSc's reduced-space active-set
// Newton (SNESVINEWTONRSLS) solves it; F is linear, A' its exact Jacobian,
// formed once per assembly of A. With friction the tangential rows of the
// frictional constraints carry the return map on the Coulomb disc
// (friction.h): F is semismooth, and the same Newton iteration decides
// open, stick and slip with its generalised Jacobian.
#pragma once

#include "contact/contact_law.h"
#include "contact/friction.h"
#include "contact/contact_set.h"
#include "contact/contact_state.h"
#include "contact/convergence.h"
#include "solvers/inactive_set_preconditioner.h"
#include "contact/change_of_variables.h"
#include "contact/schur_complement.h"
#include "solvers/solver.h"

#include <array>
#include <dolfinx/fem/Function.h>
#include <functional>
#include <map>
#include <memory>
#include <petscsnes.h>
#include <string>
#include <tuple>
#include <vector>

namespace biotcontact
{

/// Finds the contact constraints of the scene: its contact boundaries
/// against their foundations (foundation_pair.h), then the faults' node
/// pairs (fault_pair.h). Throws SceneError, the same on every rank, for the
/// first bad input they find (collective).
ContactSet locate_contact(const Scene& scene, const Domain& domain, const CompiledForms& forms,
                          std::shared_ptr<const dolfinx::fem::FunctionSpace> V);

/// @brief The matrices of the contact problem: A, and P (A, or the
/// fixed-stress matrix of the coupled system) that the iterative full path
/// builds its preconditioner from.
struct ContactOperators
{
  Mat A, P;
  /// Whether A changes between most solves (the monolithic system with
  /// conduit faults, whose rows follow their apertures): then forming H
  /// anew each time costs more than it saves, and the full path is the
  /// default.
  bool changing = false;
};

/// @brief What the contact solver constrains: the contact set, where each
/// owned DOF of V sits in the solved vector x (`displacement_dofs`: i itself
/// for the mechanics system, its place in the mixed space for the
/// monolithic one), `layout`, a vector like x, and x's separate rows
/// (local): rows in other units than the forces, whose residual is judged
/// by their own load (convergence.h).
struct ContactUnknowns
{
  ContactSet set;
  std::vector<std::int32_t> displacement_dofs;
  Vec layout;
  std::vector<std::int32_t> separate_rows = {};
};

/// The reduced-space Newton method solves, at each step, the system on the
/// inactive set (the DOFs not held on a bound). It runs in one of two ways:
///
/// - condensed (the default with a direct solver, at most
///   `max_condensed_dofs` contact DOFs and an A that is not
///   ContactOperators::changing): on the Schur complement H of A on
///   the contact DOFs (schur_complement.h). The large matrix is factorised
///   once per operator, with the contact DOFs clamped, whatever the active
///   set; the Newton steps work on the small dense H (options prefix
///   `<prefix>contact_`, log stage `<system>_contact`); a solve costs two
///   back-solves of the large system.
/// - full (`-<prefix>contact_condensed false`, or an iterative solver): on
///   A itself (options prefix `<prefix>`). The factorisation of the
///   inactive-set submatrix (or, iterative, the AMG of
///   inactive_set_preconditioner.h) is valid for as long as the inactive
///   set is: it is redone only when the set changes (PETSc resets the
///   preconditioner then) or when A is reassembled (operator_changed).
///
/// Either way each solve starts from the previous solution, whose inactive
/// set is usually the one of the new solution.
class ContactSolver
{
public:
  /// Above this many contact DOFs the dense H (m^2 doubles, m back-solves
  /// to form, m^3/3 flops per active-set change) costs more than
  /// refactorising the sparse inactive-set matrix.
  static constexpr PetscInt max_condensed_dofs = 2000;

  /// `displacement_dofs[i]` is the position of V's owned DOF i in the
  /// solved vector (i itself for the mechanics system, its place in the
  /// mixed space for the monolithic one): they locate the contact DOFs and
  /// the transformed nodes, and set the length scale. `layout` is a vector
  /// like x. On the iterative full path the Newton steps are
  /// preconditioned from P (A, or the fixed-stress matrix of the coupled
  /// system) split along `fields` (inactive_set_preconditioner.h).
  ContactSolver(MPI_Comm comm, const SystemLayout& system, Method method, ContactOperators operators,
                ContactUnknowns unknowns);
  ~ContactSolver();
  ContactSolver(const ContactSolver&) = delete;
  ContactSolver& operator=(const ContactSolver&) = delete;

  /// Solves the VI; x holds the initial guess on entry. Throws SolverError.
  /// With friction, the slip increments of the frictional constraints are
  /// measured from the slip reference (friction.h).
  void solve(Vec b, Vec x);

  /// A time step (or window) starts at x: the slip increments (friction's,
  /// and those fault.xdmf writes) are measured from it (collective).
  void set_slip_reference(Vec x);

  /// A was reassembled: the next solve factorises anew.
  void operator_changed();

  /// Solves to `relative` (iterative full path): the Krylov tolerance of
  /// each Newton step and the Newton tolerance both. F is linear (but with
  /// friction), so on an unchanged active set one step with a linear
  /// solve to `relative` meets it; a tighter Newton tolerance would only add
  /// steps.
  void set_tolerance(double relative);

  /// The contact nodes on the foundation to round-off (the active flag of
  /// state(), without the contact forces; collective).
  ActiveSet active_set(Vec x) const;

  /// Contact diagnostics of x (collective); fills the output fields.
  ContactState state(Vec x, Vec b, dolfinx::fem::Function<double>& pressure,
                     dolfinx::fem::Function<double>& active);

  const ContactSet& set() const { return _set; }
  /// "condensed on m contact DOFs" or "full".
  std::string method() const;
  /// Preconditioner set-ups of the iterative full path (-1 otherwise: then
  /// PETSc's PCSetUp events count them).
  long preconditioner_setups() const { return _preconditioner ? _preconditioner->setups : -1; }
  double preconditioner_setup_time() const { return _preconditioner ? _preconditioner->setup_time : 0; }
  /// Right-hand sides solved, partial factorisations and seconds spent
  /// forming H (0 when full).
  long schur_columns() const { return _schur ? _schur->columns : 0; }
  long schur_factorizations() const { return _schur ? _schur->factorizations : 0; }
  double schur_time() const { return _schur ? _schur->time : 0; }

  long newton_iterations = 0, linear_iterations = 0;
  /// Newton steps whose inactive set differed from the previous step's
  /// (across solves): each may cost one factorisation.
  long active_set_changes() const { return _convergence->active_set_changes; }

  /// `told` is called after each Newton step with its number: a long
  /// solve's sign of life (the run's progress line).
  void on_newton_step(std::function<void(int)> told) { _convergence->on_newton_step = std::move(told); }

private:
  /// The contact DOFs of the VI: each constraint's, then the tangential
  /// ones of the frictional constraints.
  std::vector<std::int32_t> contact_dofs() const;
  /// The frictional constraints, once the VI is posed.
  void make_friction();
  /// The VI with the current bounds and load; retried from the clamped
  /// state when the first attempt fails; throws when both do.
  void solve_vi();
  /// F += the friction forces at x (F holds R on entry); a step of the
  /// residual callback, so it returns PETSc's error code.
  PetscErrorCode add_friction(Vec x, Vec F) const;
  void condense();
  void pose_on_full_system(Vec layout);
  void make_bound_vectors();
  void create_snes(const std::string& vi_prefix);
  /// Whether the Newton steps reuse the preconditioner until the inactive
  /// set or the operator changes: always but for a factorisation of the
  /// Jacobian of friction, which changes every step.
  bool lag_preconditioner() const { return !_J or _preconditioner_on_P; }
  void set_bounds();
  void pose(Vec b, Vec x);
  void count_iterations(SNESConvergedReason reason);
  /// Sets the unknown of the VI to the solution with every contact DOF on
  /// its bound.
  void clamped_start();
  /// The largest gap or displacement (collective): SNES works in its units.
  double displacement_scale(Vec x) const;
  /// Runs SNESSolve on the unknown of the VI; throws on a PETSc error.
  SNESConvergedReason run_snes();
  static PetscErrorCode residual(SNES, Vec x, Vec F, void* context);
  static PetscErrorCode jacobian(SNES, Vec, Mat, Mat, void*);
  std::vector<char> active_contact_dofs(Vec x, bool* clipped = nullptr) const;
  /// The change of variables of the inclined and curved foundations, made
  /// when any node needs one (collective), and the operators it makes.
  void make_change_of_variables(Vec layout);
  /// The global position in the solved vector of each global DOF of V in
  /// `dofs`, wherever it is owned (collective).
  std::vector<PetscInt> solved_positions(const std::vector<std::int64_t>& dofs, Vec layout) const;
  /// A' and P' of the current A and P (after a reassembly).
  void change_operators();
  /// x' = T x (x itself without a change of variables).
  Vec to_vi(Vec x, Vec work) const;
  /// The distance g - u.nu_F of each constraint at x (in x's units).
  std::vector<double> distances(Vec x) const;

  MPI_Comm _comm;
  Mat _A, _P;
  // The VI's operators: A' and P' of the change of variables, or A and P.
  std::unique_ptr<ChangeOfVariables> _change;
  Mat _A_vi, _P_vi;
  bool _change_current = false;
  Vec _x_vi = nullptr, _b_vi = nullptr; // x' and b' (work vectors when changed)
  std::vector<Field> _fields;
  Structure _structure;
  std::string _prefix;
  bool _lag_by_default = false;
  bool _preconditioner_on_P = false; // the iterative full path: built from P, not from the Jacobian
  PetscBool _snes_rtol_given = PETSC_FALSE; // -<prefix>snes_rtol on the command line
  ContactSet _set;
  std::vector<std::int32_t> _dofs, _displacement_dofs;
  std::vector<std::int32_t> _separate_rows; // ContactUnknowns::separate_rows, until the VI is posed
  Vec _force; // like x: A x - b

  // The VI that SNES solves: on (A, b) or on (H, g). Its unknown carries
  // bounds at `_bounded` (the contact DOFs in its numbering) with gaps
  // `_bounded_gap`; it lives on `_vi_comm` (PETSC_COMM_SELF when condensed:
  // every rank solves the same small problem).
  std::unique_ptr<SchurComplement> _schur;
  bool _schur_current = false;
  std::unique_ptr<SolverStage> _vi_stage;
  MPI_Comm _vi_comm;
  Mat _K;
  std::vector<std::int32_t> _bounded;
  std::vector<double> _bounded_gap, _bounded_sign;
  Vec _lower, _upper, _x, _residual, _b_scaled;
  double _scale = 1; // SNES works in units of the displacement scale
  SNES _snes;
  std::unique_ptr<InactiveSetPreconditioner> _preconditioner;
  std::unique_ptr<ContactConvergence> _convergence;
  // Friction: its constraints, the start of the step (in the VI's
  // numbering, unscaled), the diagonal of K (the stiffness that turns a slip
  // increment into a trial force) and a work vector.
  std::vector<FrictionalConstraint> _friction;
  Vec _x_reference = nullptr, _stiffness = nullptr, _work = nullptr;
  // The start of the step like x, and x' of it (the faults' slip increments).
  Vec _x_start = nullptr, _x_start_vi = nullptr;
  Mat _J = nullptr; // friction: the generalised Jacobian (friction.h)
};

} // namespace biotcontact
