// One quasi-static mechanics solve: linear elasticity loaded by the pore
// pressure, with frictionless Signorini contact against a rigid foundation
// when the scene has a contact boundary (alg. "Mechanics with frictionless
// Signorini contact", paper eq. 3.16).
//
// The energy 1/2 a(u,u) - (alpha p, div u) - (f0, u) - <f2, u> is quadratic,
// so with A the matrix of a(.,.) and b the load vector the variational
// inequality is the bound-constrained problem
//     find u with  l <= u <= g_u  and  F(u) = A u - b  complementary,
// where the bounds sit only on the DOF of each contact node along the
// foundation normal: u.nu_F <= g_a (nu_F = +-e_i). PETSc's reduced-space
// active-set Newton (SNESVINEWTONRSLS) solves it; F is linear, so A is the
// exact Jacobian and is assembled once. Without contact it is a linear solve.
#pragma once

#include "domain.h"
#include "forms.h"
#include "linear_algebra.h"
#include "parameters.h"

#include <dolfinx/fem/Form.h>
#include <dolfinx/fem/Function.h>
#include <memory>
#include <optional>
#include <petscsnes.h>

namespace biotcontact
{

/// The contact state after a solve (alg.: the contact force at an active node
/// is the residual there; divided by the lumped boundary measure it is the
/// contact pressure -sigma_nu >= 0).
struct ContactState
{
  int active_nodes = 0;
  int contact_nodes = 0;
  double max_penetration = 0;     // max(u.nu_F - g_a), <= 0 when admissible
  double max_pressure = 0;        // max contact pressure
  double min_pressure = 0;        // min contact pressure (>= 0 up to tolerance)
  double max_complementarity = 0; // max |p_c (u.nu_F - g_a)|
  double gap_scale = 0;           // max(|g_a|, |u.nu_F|) over contact nodes
};

class MechanicsStep
{
public:
  /// `V` is the P1 displacement space; `pressure` the pore pressure of a
  /// coupled scene, null otherwise.
  MechanicsStep(const Scene& scene, const Domain& domain, const CompiledForms& forms,
                const Constants& constants, std::shared_ptr<const dolfinx::fem::FunctionSpace> V,
                std::shared_ptr<const dolfinx::fem::Function<double>> pressure);
  ~MechanicsStep();
  MechanicsStep(const MechanicsStep&) = delete;
  MechanicsStep& operator=(const MechanicsStep&) = delete;

  /// Solves at time t with the current pressure; leaves the result in u.
  void solve(double t);

  /// Contact diagnostics of the current u (collective); also fills the
  /// contact pressure and active-flag fields.
  ContactState contact_state();

  std::shared_ptr<const dolfinx::fem::FunctionSpace> space() const { return _V; }
  bool has_contact() const { return _contact.has_value(); }

  std::shared_ptr<dolfinx::fem::Function<double>> u;
  /// On the P1 scalar space of the contact component; zero off Gamma_3.
  std::shared_ptr<dolfinx::fem::Function<double>> contact_pressure, contact_active;

  int solves = 0;
  long linear_iterations = 0, newton_iterations = 0;
  double assembly_time = 0, solve_time = 0;

private:
  struct Contact
  {
    int axis, sign;
    std::vector<std::int32_t> dofs; // owned DOFs of the contact component
    std::vector<double> gap;        // g_a at those DOFs
    std::vector<double> lumped;     // lumped boundary measure there
    std::vector<std::int32_t> collapsed; // matching DOFs of the output space
    Vec lower, upper, x, residual, b_scaled; // SNES works in units of `scale`
    double scale = 1;
    SNES snes;
  };

  void assemble_rhs(double t);
  static PetscErrorCode residual(SNES, Vec x, Vec F, void* context);
  static PetscErrorCode jacobian(SNES, Vec, Mat, Mat, void*);

  const Scene& _scene;
  std::shared_ptr<const dolfinx::fem::FunctionSpace> _V;
  BCs _bcs;
  struct DisplacementBC
  {
    const Expression* value;
    std::shared_ptr<dolfinx::fem::Function<double>> g;
  };
  std::vector<DisplacementBC> _bc_values;
  std::shared_ptr<dolfinx::fem::Function<double>> _body_force, _traction;
  std::shared_ptr<dolfinx::fem::Form<double>> _a, _L_pressure, _L_body;
  std::vector<std::pair<const std::vector<Expression>*, std::shared_ptr<dolfinx::fem::Form<double>>>> _L_traction;
  std::vector<std::shared_ptr<const dolfinx::mesh::MeshTags<std::int32_t>>> _markers;
  std::optional<dolfinx::la::petsc::Matrix> _A;
  std::unique_ptr<LinearSolver> _solver;
  std::unique_ptr<dolfinx::la::Vector<double>> _b, _b_loads;
  bool _loads_depend_on_time = false;
  bool _loads_assembled = false;
  double _loads_time = -1;
  std::optional<Contact> _contact;
};

} // namespace biotcontact
