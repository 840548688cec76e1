// One quasi-static mechanics solve: linear elasticity loaded by the pore
// pressure (paper eq. 3.16), with frictionless Signorini contact (contact.h)
// when the scene has a contact boundary, a plain linear solve otherwise.
#pragma once

#include "assembly/boundary_conditions.h"
#include "assembly/fault_aperture.h"
#include "contact/contact.h"
#include "domain/domain.h"
#include "assembly/forms.h"
#include "assembly/linear_algebra.h"
#include "assembly/loads.h"
#include "assembly/materials.h"
#include "assembly/parameters.h"
#include "assembly/problem.h"
#include "steps/seismic_moments.h"
#include "steps/step.h"
#include "steps/system.h"

#include <dolfinx/fem/Form.h>
#include <dolfinx/fem/Function.h>
#include <memory>
#include <optional>

namespace biotcontact
{

/// @brief The mechanics step: quasi-static linear elasticity loaded by the
/// pore pressure, with contact where the scene has it.
class MechanicsStep : public Step
{
public:
  /// `V` is the P1 displacement space; `pressure` the pore pressure of a
  /// coupled scene, null otherwise (then the step makes `given_pressure`
  /// from mechanics.pore_pressure, if the scene gives one).
  MechanicsStep(const Problem& problem, std::shared_ptr<const dolfinx::fem::FunctionSpace> V,
                std::shared_ptr<const dolfinx::fem::Function<double>> pressure);
  ~MechanicsStep();
  MechanicsStep(const MechanicsStep&) = delete;
  MechanicsStep& operator=(const MechanicsStep&) = delete;

  /// Solves at time t with the current pressure; leaves the result in u.
  void solve(double t);

  std::string name() const override { return "mechanics"; }
  /// solve(t): the mechanics has no time derivative.
  void advance(double t, const TimeDerivative&) override
  {
    recorded_solve(true, [&] { solve(t); });
  }
  /// The solve at t = 0.
  std::vector<SolveRecord> equilibrate() override
  {
    advance(0.0, {});
    return solves();
  }
  void begin_step() override;
  StepState state() const override { return {values(unknowns()), {}, {}}; }
  void restore(const StepState& start) override { set_unknowns(start.unknowns); }
  std::span<const double> unknowns() const override { return u->x()->array(); }
  void set_unknowns(std::span<const double> x) override { assign(*u, x); }
  std::vector<UnknownsPart> parts() const override { return {{"displacement", _V, {}}}; }
  std::span<const double> displacement_values() const override { return u->x()->array(); }
  bool same_contact_set(const ActiveSet& before) override;

  /// Contact diagnostics of the current u (collective); also fills the
  /// contact pressure and active-flag fields.
  ContactState contact_state();
  /// Only the contact active set of u (collective, cheap: no contact
  /// forces), for the log of every coupling iteration; empty without
  /// contact.
  ActiveSet active_contact_set() override;
  /// ContactSolver::pin, and its consistent_pins at the current u
  /// (collective; none without contact).
  void pin_contact(std::vector<std::int8_t> pins);
  std::vector<std::int8_t> consistent_pins();
  /// Changes of the contact active set so far (0 without contact).
  long active_set_changes() { return system().has_contact() ? system().contact().active_set_changes() : 0; }

  /// The conduit faults' pressure p_f (this rank's entries) pushes their faces
  /// apart at every solve from now on, by the load of `aperture`.
  void load_fault_pressure(const FaultAperture& aperture, const std::vector<double>& p_f)
  {
    _fault_load = {&aperture, &p_f};
  }
  /// The conduit cells' effective normal stress s_n at the last solve: the
  /// mean contact traction of their pairs (FaultAperture::cell_means; every
  /// cell on every rank), computed only where a conduit has a closure.
  const std::vector<double>& fault_traction() const { return _fault_traction; }

  /// The accepted step's seismic moment, per fault (FaultSummary::moment),
  /// joins the run's record.
  void accept(double t) override;
  /// The record of the faults' seismic moments, "seismic_moments" (a
  /// checkpoint's), and the conduit cells' s_n, "fault_traction"; and
  /// their restoration.
  std::map<std::string, std::vector<double>> arrays() const override;
  void restore_arrays(const std::map<std::string, std::vector<double>>& arrays) override;
  /// The faults' seismic moments of every accepted step: the faults'
  /// names, then per step its time and each fault's moment.
  const SeismicMoments& seismic_moments() const { return _moments; }

  std::shared_ptr<const dolfinx::fem::FunctionSpace> space() const { return _V; }
  bool has_contact() const { return _system->has_contact(); }
  const System& system() const override { return *_system; }
  System& system() override { return *_system; }

  std::shared_ptr<dolfinx::fem::Function<double>> u;
  /// One-way coupling: the pore pressure mechanics.pore_pressure gives, in
  /// P0 at the cell midpoints, at the time of the last solve; null otherwise.
  std::shared_ptr<dolfinx::fem::Function<double>> given_pressure;
  /// On the P1 scalar space of the contact component; zero off Gamma_3.
  std::shared_ptr<dolfinx::fem::Function<double>> contact_pressure, contact_active, contact_boundary;

protected:
  SolveFields solve_fields() const override
  {
    return {{}, {u->x()->array(), owned_size(*_V), true}, {}, _V->mesh()->comm()};
  }

private:
  void make_loads(const Domain& domain, const CompiledForms& forms, const Constants& constants);
  void add_fault_pressures(const Domain& domain, const CompiledForms& forms, const Constants& constants);
  void attach_contact(const Domain& domain, const CompiledForms& forms, const Materials& materials);
  void assemble_rhs(double t);

  const Scene& _scene;
  std::shared_ptr<const dolfinx::fem::FunctionSpace> _V;
  BCs _bcs;
  std::vector<DisplacementValue> _bc_values;
  std::shared_ptr<dolfinx::fem::Form<double>> _a;
  std::shared_ptr<const dolfinx::fem::Function<double>> _pressure;
  std::optional<dolfinx::la::petsc::Matrix> _pressure_load; // V x Q
  std::unique_ptr<System> _system;
  std::unique_ptr<dolfinx::la::Vector<double>> _b;
  std::unique_ptr<Loads> _loads; // body force, tractions
  struct
  {
    const FaultAperture* aperture = nullptr;
    const std::vector<double>* pressure = nullptr;
  } _fault_load; // the conduit faults' pressure on their faces
  SeismicMoments _moments;
  bool _closure = false;               // whether a conduit fault's aperture follows its normal stress
  std::vector<double> _fault_traction; // s_n per conduit cell at the last solve
};

} // namespace biotcontact
