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

#include "domain.h"
#include "forms.h"
#include "solver.h"

#include <dolfinx/fem/Function.h>
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
/// inactive set (the DOFs not held on a bound). A is constant, so the
/// factorisation of that submatrix is valid for as long as the inactive set
/// is: it is redone only when the set changes (PETSc resets the
/// preconditioner then) or when A is reassembled (operator_changed), and
/// each solve starts from the previous solution, whose inactive set is
/// usually the one of the new solution.
class ContactSolver
{
public:
  /// `dofs` are the contact DOFs of `set` in the numbering of the solved
  /// vector (the same as set.dofs for the mechanics system, mapped into the
  /// mixed space for the monolithic one); `displacement_dofs` the owned
  /// displacement DOFs there (they set the length scale). `layout` is a
  /// vector like x.
  ContactSolver(MPI_Comm comm, const std::string& prefix, Mat A, Structure structure, Vec layout,
                ContactSet set, std::vector<std::int32_t> dofs, std::vector<std::int32_t> displacement_dofs);
  ~ContactSolver();
  ContactSolver(const ContactSolver&) = delete;
  ContactSolver& operator=(const ContactSolver&) = delete;

  /// Solves the VI; x holds the initial guess on entry. Throws SolverError.
  void solve(Vec b, Vec x);

  /// A was reassembled: the next Newton step factorises anew.
  void operator_changed();

  /// The number of contact nodes on the foundation to round-off (the
  /// active flag of state(), without the contact forces; collective).
  int active_nodes(Vec x) const;

  /// Contact diagnostics of x (collective); fills the output fields.
  ContactState state(Vec x, Vec b, dolfinx::fem::Function<double>& pressure,
                     dolfinx::fem::Function<double>& active);

  const ContactSet& set() const { return _set; }
  long newton_iterations = 0, linear_iterations = 0;
  /// Newton steps whose inactive set differed from the previous step's
  /// (across solves): each may cost one factorisation.
  long active_set_changes = 0;

private:
  /// Sets x to the solution with every contact DOF on its bound.
  void clamped_start(Vec b);
  /// The largest gap or displacement (collective): SNES works in its units.
  double displacement_scale(Vec x) const;
  static PetscErrorCode residual(SNES, Vec x, Vec F, void* context);
  static PetscErrorCode jacobian(SNES, Vec, Mat, Mat, void*);
  /// Called before each Newton step (and after the last): records the
  /// active set the next step will use, by PETSc's own rule
  /// (SNESVIGetActiveSetIS), and counts changes.
  static PetscErrorCode monitor(SNES, PetscInt iteration, PetscReal, void* context);
  std::vector<char> active_contact_dofs(Vec x) const;

  MPI_Comm _comm;
  Mat _A;
  Structure _structure;
  std::string _prefix;
  bool _lag_by_default = false;
  std::vector<char> _pending, _used; // active flags of the contact DOFs
  bool _any_used = false;
  ContactSet _set;
  std::vector<std::int32_t> _dofs, _displacement_dofs;
  Vec _lower, _upper, _x, _residual, _b_scaled;
  double _scale = 1; // SNES works in units of the displacement scale
  SNES _snes;
};

} // namespace biotcontact
