// Signorini contact against rigid foundations of any normal nu_F and
// between a fault's faces (alg. "Mechanics with frictionless Signorini
// contact"; friction: contact_law.h). The energy is quadratic: with A the
// matrix of the (mechanics or monolithic) system and b its load, each
// constraint u.nu_F <= g_a is a bound on one DOF of x' = T x
// (change_of_variables.h), and the contact is the variational inequality
// of variational_inequality.h on (A' = T^-T A T^-1, b' = T^-T b), or on the
// Schur complement of its contact DOFs (schur_complement.h).
#pragma once

#include "contact/bonds.h"
#include "contact/contact_law.h"
#include "contact/contact_path.h"
#include "contact/locate_contact.h"
#include "contact/friction.h"
#include "contact/load_continuation.h"
#include "contact/contact_set.h"
#include "contact/contact_state.h"
#include "contact/change_of_variables.h"
#include "contact/schur_complement.h"
#include "contact/variational_inequality.h"
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
  /// Whether the run solves the contact once (one step of the mechanics
  /// alone): then by default the whole system's first Newton step (two
  /// with friction) is tried before the condensed path (contact.cpp).
  bool once = false;
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
/// A run that solves the contact once (ContactOperators::once) starts on the
/// full path for one Newton step, and goes on condensed if that step did
/// not solve the VI: a solve whose active set is right at once costs one
/// factorisation, where the condensed path costs three to five (A's, and
/// the partial one that forms H). Where the full path is the default but
/// the condensed one open (ContactPathChoice), a full solve that fails is
/// solved again condensed from its start, and the run goes on condensed.
///
/// Either way each solve starts from the previous solution, whose inactive
/// set is usually the one of the new solution.
class ContactSolver
{
public:
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

  /// The step (or window) ending at x was accepted: the bonds of the pairs
  /// open at x break, and the bonds as they are now hold from the next
  /// step on (contact_law.h; collective).
  void accept_step(Vec x);
  /// The names (constraint_keys) of the constraints whose cohesion held
  /// and broke by the last accepted step, on every rank, for a checkpoint
  /// (collective); and their restoration.
  std::vector<double> broken_bonds() const { return broken_bond_names(_set, _bonded_accepted, _comm); }
  void restore_bonds(const std::vector<double>& broken);

  /// From the next solve on, each constraint k of the set (this rank's) is
  /// pinned closed (pins[k] = 1: on its bound, whatever its force), pinned
  /// open (-1: unbounded) or free (0); empty on every rank: none pinned
  /// (collective; coupling/pins.h).
  void pin(std::vector<std::int8_t> pins);
  /// The pins at x under load b, those x contradicts turned: a constraint
  /// pinned open that penetrates by more than pin_tolerance
  /// (contact_pins.cpp) of the displacement scale is pinned closed, one
  /// pinned closed that pulls by more than that of the largest contact
  /// pressure is pinned open (this rank's; collective).
  std::vector<std::int8_t> consistent_pins(Vec x, Vec b);

  /// A was reassembled: the next solve factorises anew.
  void operator_changed();
  /// A few rows of A changed (a conduit fault's apertures): the last
  /// factorisation may precondition GMRES on it (VariationalInequality).
  void operator_nudged() { _schur_current = _change_current = false, _solved.forget(), _vi->operator_nudged(); }

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
  /// Whether the full path's Newton steps run GMRES on the last
  /// factorisation instead of the system's own solver (VariationalInequality).
  bool reuses_factorization() const { return !_schur and _vi->reuses_factorization(); }
  /// Preconditioner set-ups of the iterative full path (-1 otherwise: then
  /// PETSc's PCSetUp events count them).
  long preconditioner_setups() const { return _vi->preconditioner_setups(); }
  double preconditioner_setup_time() const { return _vi->preconditioner_setup_time(); }
  /// Right-hand sides solved, partial factorisations and seconds spent
  /// forming H (0 when full).
  long schur_columns() const { return _schur ? _schur->columns : 0; }
  long schur_factorizations() const { return _schur ? _schur->factorizations : 0; }
  /// The condensed VI's factorisations (0 on the full path, whose
  /// factorisations are the system's).
  long contact_factorizations() const { return _vi->factorizations(); }
  double schur_time() const { return _schur ? _schur->time : 0; }

  /// Newton steps and Krylov iterations (1 per back-solve when direct).
  long newton_iterations() const { return _vi->newton_iterations; }
  long linear_iterations() const { return _vi->linear_iterations; }
  /// Newton steps whose inactive set differed from the previous step's
  /// (across solves): each may cost one factorisation.
  long active_set_changes() const { return _vi->convergence().active_set_changes; }

  /// `told` is called after each Newton step with its number: a long
  /// solve's sign of life (the run's progress line).
  void on_newton_step(std::function<void(int)> told) { _vi->convergence().on_newton_step = std::move(told); }

private:
  /// The contact DOFs of the VI: each constraint's, then the tangential
  /// ones of the frictional constraints.
  std::vector<std::int32_t> contact_dofs() const;
  /// The VI on the Schur complement of the contact DOFs (and a new vector
  /// like its unknown, the caller's to destroy).
  VIProblem condense();
  /// The condensed VI, friction added.
  std::unique_ptr<VariationalInequality> condensed_vi();
  /// The full path's trial or solve did not converge: the VI is posed
  /// condensed from now on, the counts carried over; `after` says when
  /// (method()). Returns the full path's VI.
  std::unique_ptr<VariationalInequality> switch_to_condensed(std::string after);
  /// A failed full solve went on condensed and failed there too: the full
  /// path (its VI `full`, the one switch_to_condensed returned) again.
  void back_to_full(std::unique_ptr<VariationalInequality> full);
  /// Solves the VI for x' (in place) on the current path, and a failed
  /// full solve again condensed where the path's choice allows it.
  void solve_on_path(Vec b_vi, Vec x_vi);
  /// Solves the VI for x' (in place) from the load b': at most
  /// `newton_steps` of one attempt (0: as many as it takes, throwing
  /// SolverError if it fails); whether it converged.
  bool solve_vi(Vec b_vi, Vec x_vi, int newton_steps);
  /// The VI on the whole system.
  VIProblem pose_on_full_system(Vec layout, std::vector<std::int32_t> separate_rows) const;
  /// The frictional constraints, once the VI is posed.
  void add_friction(VIProblem& problem) const;
  /// The VI's frictional constraints with their laws as the bonds are now
  /// (collective when condensed).
  std::vector<FrictionalConstraint> frictional_constraints() const;
  /// After a failed solve: the bonds of the cohesive constraints its
  /// clamped start pulls break; whether any did (collective).
  bool break_pulled_bonds();
  /// The VI takes the bonds as they are now, if they changed on any rank;
  /// whether they did (collective).
  bool update_bonds(bool changed);
  /// The change of variables of the inclined and curved foundations, made
  /// when any node needs one (collective), and the operators it makes.
  void make_change_of_variables(Vec layout);
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
  ContactSet _set;
  std::vector<std::int32_t> _dofs, _displacement_dofs;
  Vec _force; // like x: A x - b
  // The VI: on (A', b') or, condensed, on (H, g) of the Schur complement.
  std::unique_ptr<SchurComplement> _schur;
  bool _schur_current = false;
  std::unique_ptr<VariationalInequality> _vi;
  // On the whole system until its first Newton step, or first two with
  // friction, fail to solve the VI (ContactOperators::once).
  bool _then_condensed = false;
  int _full_steps = 1;
  // A failed full solve is solved again condensed (ContactPathChoice).
  bool _condensed_on_failure = false;
  std::string _after; // when the path turned condensed ("" from the start)
  // The start of the step like x, and x' of it (the faults' slip increments).
  Vec _x_start = nullptr, _x_start_vi = nullptr;
  // The bonds as of the last accepted step (_set.bonded: as of now).
  std::vector<char> _bonded_accepted;
  // The constraints' pins (pin) and whether any rank has one.
  std::vector<std::int8_t> _pins;
  bool _pinned = false;
  /// The pins in the VI's bounded positions (collective when condensed).
  std::vector<std::int8_t> pins_in_vi() const;
  /// The contact force R' = T^-T (A x - b) at x: the multiplier of each
  /// constraint (in _force, or _b_vi with a change of variables).
  Vec contact_force(Vec x, Vec b);
  // The last load solved and its solution, where a failed solve's load
  // continuation starts.
  SolvedLoad _solved;
};

} // namespace biotcontact
