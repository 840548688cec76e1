// Frictionless Signorini contact against a rigid foundation with normal
// nu_F = +-e_i (alg. "Mechanics with frictionless Signorini contact").
//
// The energy is quadratic, so with A the matrix of the (mechanics or
// monolithic) system and b its load vector the variational inequality is the
// bound-constrained problem
//     find x with l <= x <= g and F(x) = A x - b complementary to the bounds,
// with bounds only on the DOF of each contact node along nu_F:
// u.nu_F <= g_a. PETSc's reduced-space active-set Newton (SNESVINEWTONRSLS)
// solves it; F is linear, A is its exact Jacobian, assembled once.
#pragma once

#include "domain/domain.h"
#include "assembly/forms.h"
#include "solvers/inactive_set_preconditioner.h"
#include "contact/schur_complement.h"
#include "solvers/solver.h"

#include <dolfinx/fem/Function.h>
#include <functional>
#include <memory>
#include <petscsnes.h>
#include <string>
#include <vector>

namespace biotcontact
{

/// The contact nodes of a P1 displacement space V: for each node of Gamma_3
/// (owned by this rank) the DOF along the foundation normal, its gap g_a and
/// its lumped boundary measure (which turns a nodal force into a pressure).
struct ContactSet
{
  int axis = 0, sign = 1;
  std::vector<std::int32_t> dofs; // in V (unrolled)
  std::vector<double> gap, lumped;
  /// The P1 scalar space of the normal component, for output, and the
  /// matching DOF of each contact node there.
  std::shared_ptr<const dolfinx::fem::FunctionSpace> output_space;
  std::vector<std::int32_t> output_dofs;
};

/// The contact boundary as a P1 field for output: exactly 1 at the contact
/// nodes, 0 elsewhere.
std::shared_ptr<dolfinx::fem::Function<double>> contact_boundary_flag(const ContactSet& set);

/// The output fields of a contact set: the contact pressure and active flag
/// (zero off Gamma_3) and the contact_boundary_flag.
void make_contact_fields(const ContactSet& set, std::shared_ptr<dolfinx::fem::Function<double>>& pressure,
                         std::shared_ptr<dolfinx::fem::Function<double>>& active,
                         std::shared_ptr<dolfinx::fem::Function<double>>& boundary);

/// Finds the contact nodes of the scene's contact boundaries (all must share
/// one foundation normal; throws SceneError otherwise).
ContactSet locate_contact(const Scene& scene, const Domain& domain, const CompiledForms& forms,
                          std::shared_ptr<const dolfinx::fem::FunctionSpace> V);

/// The contact state after a solve: the contact force at a node is the
/// residual of the unconstrained equations there; divided by the lumped
/// measure it is the contact pressure -sigma_nu >= 0.
struct ContactState
{
  int active_nodes = 0;
  int contact_nodes = 0;
  double max_penetration = 0;     // max(u.nu_F - g_a), <= 0 when admissible
  double max_pressure = 0;        // max contact pressure
  double min_pressure = 0;        // min contact pressure (>= 0 up to tolerance)
  double max_complementarity = 0; // max |p_c (u.nu_F - g_a)|
  double gap_scale = 0;           // max(|g_a|, |u|)
  double total_force = 0;         // sum of the nodal contact forces along -nu_F
};

/// The reduced-space Newton method solves, at each step, the system on the
/// inactive set (the DOFs not held on a bound). It runs in one of two ways:
///
/// - condensed (the default with a direct solver and at most
///   `max_condensed_dofs` contact DOFs): on the Schur complement H of A on
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
  /// A Krylov solve of a Newton step on the iterative full path that
  /// reduces its residual by less than 1% over this many iterations has
  /// stagnated (contact.cpp, stagnation).
  static constexpr PetscInt stagnation_window = 50;

  /// `dofs` are the contact DOFs of `set` in the numbering of the solved
  /// vector (the same as set.dofs for the mechanics system, mapped into the
  /// mixed space for the monolithic one); `displacement_dofs` the owned
  /// displacement DOFs there (they set the length scale). `layout` is a
  /// vector like x. On the iterative full path the Newton steps are
  /// preconditioned from P (A, or the fixed-stress matrix of the coupled
  /// system) split along `fields` (inactive_set_preconditioner.h).
  ContactSolver(MPI_Comm comm, const std::string& prefix, Mat A, Mat P, const std::vector<Field>& fields,
                Structure structure, Method method, Vec layout, ContactSet set, std::vector<std::int32_t> dofs,
                std::vector<std::int32_t> displacement_dofs);
  ~ContactSolver();
  ContactSolver(const ContactSolver&) = delete;
  ContactSolver& operator=(const ContactSolver&) = delete;

  /// Solves the VI; x holds the initial guess on entry. Throws SolverError.
  void solve(Vec b, Vec x);

  /// A was reassembled: the next solve factorises anew.
  void operator_changed();

  /// Solves to `relative` (iterative full path): the Krylov tolerance of
  /// each Newton step and the Newton tolerance both. F is linear, so on an
  /// unchanged active set one step with a linear solve to `relative` meets
  /// it; a tighter Newton tolerance would only add steps.
  void set_tolerance(double relative);

  /// The number of contact nodes on the foundation to round-off (the
  /// active flag of state(), without the contact forces; collective).
  int active_nodes(Vec x) const;

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
  /// Right-hand sides solved and seconds spent forming H (0 when full).
  long schur_columns() const { return _schur ? _schur->columns : 0; }
  double schur_time() const { return _schur ? _schur->time : 0; }

  long newton_iterations = 0, linear_iterations = 0;
  /// Newton steps whose inactive set differed from the previous step's
  /// (across solves): each may cost one factorisation.
  long active_set_changes = 0;

  /// Called after each Newton step with its number: a long solve's sign of
  /// life (the run's progress line).
  std::function<void(int)> on_newton_step;

private:
  void condense();
  void pose_on_full_system(Vec layout);
  void make_bound_vectors();
  void create_snes(const std::string& vi_prefix);
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
  /// Called before each Newton step (and after the last): records the
  /// active set the next step will use, by PETSc's own rule
  /// (SNESVIGetActiveSetIS), and counts changes.
  static PetscErrorCode monitor(SNES, PetscInt iteration, PetscReal, void* context);
  /// PETSc's convergence test of the VI methods, and stop when a step kept
  /// its active set (the solution on that set: see contact.cpp).
  static PetscErrorCode converged(SNES, PetscInt iteration, PetscReal, PetscReal, PetscReal fnorm,
                                  SNESConvergedReason* reason, void* context);
  /// KSP monitor of the Newton steps (iterative full path): stops a Krylov
  /// solve that stagnates.
  static PetscErrorCode stagnation(KSP, PetscInt iteration, PetscReal rnorm, void* context);
  std::vector<char> active_contact_dofs(Vec x) const;

  MPI_Comm _comm;
  Mat _A, _P;
  std::vector<Field> _fields;
  Structure _structure;
  std::string _prefix;
  bool _lag_by_default = false;
  PetscBool _snes_rtol_given = PETSC_FALSE; // -<prefix>snes_rtol on the command line
  std::vector<char> _pending, _used; // active flags of the contact DOFs
  bool _any_used = false;
  bool _set_repeated = false;    // the last step's result keeps the set it used
  PetscReal _relative_target = 0; // rtol times the first residual of a solve
  std::vector<PetscReal> _residuals; // of the current Krylov solve (stagnation)
  PetscInt _lowered_from = 0;        // the iteration limit before a stagnated solve lowered it
  ContactSet _set;
  std::vector<std::int32_t> _dofs, _displacement_dofs;
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
  std::vector<double> _bounded_gap;
  Vec _lower, _upper, _x, _residual, _b_scaled;
  double _scale = 1; // SNES works in units of the displacement scale
  SNES _snes;
  std::unique_ptr<InactiveSetPreconditioner> _preconditioner;
};

} // namespace biotcontact
