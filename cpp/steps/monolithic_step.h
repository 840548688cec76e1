// The monolithic reference (alg. "Monolithic reference"): each backward-Euler
// step solves mechanics and flow together, one variational inequality in
// (u, z, p) on the mixed space P1^d x RT0 x P0, with bounds only on the
// contact DOFs. It is what the fixed-stress split converges to. Conduit
// faults append their pressure p_f (monolithic_conduits.h), and each step
// iterates on their apertures.
#pragma once

#include "assembly/boundary_conditions.h"
#include "assembly/wells.h"
#include "contact/contact.h"
#include "domain/domain.h"
#include "assembly/forms.h"
#include "assembly/linear_algebra.h"
#include "assembly/loads.h"
#include "assembly/materials.h"
#include "assembly/parameters.h"
#include "assembly/problem.h"
#include "steps/monolithic_conduits.h"
#include "steps/seismic_moments.h"
#include "steps/step.h"
#include "steps/system.h"
#include "time/time_scheme.h"

#include <dolfinx/fem/Form.h>
#include <dolfinx/fem/Function.h>
#include <memory>
#include <optional>

namespace biotcontact
{

/// @brief The monolithic step: displacement, flux and pressure in one system.
class MonolithicStep : public Step
{
public:
  explicit MonolithicStep(const Problem& problem);
  ~MonolithicStep();
  MonolithicStep(const MonolithicStep&) = delete;
  MonolithicStep& operator=(const MonolithicStep&) = delete;

  /// One step to time t from the state now in u and pressure, with the
  /// time derivative `d` of the accumulation (time/time_scheme.h; BDF2
  /// reads u_before and p_before, the state one step before).
  void solve(double t, const TimeDerivative& d = {});

  std::string name() const override { return "monolithic"; }
  void advance(double t, const TimeDerivative& d) override { solve(t, d); }
  /// The coupled system has no mechanics system of its own: one mechanics
  /// step on its displacement space, loaded by its pressure, solved once.
  std::vector<SolveRecord> equilibrate() override;
  void begin_step() override;
  StepState state() const override;
  void restore(const StepState& start) override { set_unknowns(start.unknowns); }
  /// p_before and u_before take the accepted step's start.
  void keep_history(const StepState& start) override;
  /// BDF2: p_before and u_before.
  History history() const override;
  /// The accepted step's seismic moment, per fault, joins the run's record.
  void accept(double t) override;
  /// A conduit fault the step to t would leave unbalanced, or empty.
  std::string unbalanced(double t) const override;
  /// The record of the faults' seismic moments, "seismic_moments" (a
  /// checkpoint's), the conduit faults' arrays (FlowStep::arrays) and
  /// their cells' s_n, "fault_traction"; and their restoration.
  std::map<std::string, std::vector<double>> arrays() const override;
  void restore_arrays(const std::map<std::string, std::vector<double>>& arrays) override;
  /// The faults' seismic moments of every accepted step.
  const SeismicMoments& seismic_moments() const { return _moments; }
  /// The conduit faults' cell fields at t on rank 0 and their volumes
  /// (FlowStep::fault_flow and fault_volumes; empty without conduits).
  std::vector<double> fault_flow(double t) const;
  std::vector<std::pair<std::string, FaultVolumes>> fault_volumes() const;
  /// Where the conduit faults meet, and the rates through (FlowStep's).
  std::vector<IntersectionRate> fault_intersections() const;
  std::span<const double> pressure_values() const override { return pressure->x()->array(); }
  std::span<const double> displacement_values() const override { return u->x()->array(); }
  bool same_contact_set(const ActiveSet& before) override;

  void flux(dolfinx::fem::Function<double>& out) const;

  /// The matrix depends on dt: reassembled (and refactorised at the next
  /// solve) after set_time_step changed the "dt" constant.
  void time_step_changed() override;
  ContactState contact_state();
  /// Only the contact active set (collective, cheap); empty without contact.
  ActiveSet active_contact_set() override;
  bool has_contact() const { return _system->has_contact(); }
  const System& system() const override { return *_system; }
  System& system() override { return *_system; }

  std::shared_ptr<const dolfinx::fem::FunctionSpace> V, Q;
  std::shared_ptr<dolfinx::fem::Function<double>> u, pressure;
  std::shared_ptr<dolfinx::fem::Function<double>> u_before, p_before; // BDF2's memory; checkpointed
  std::shared_ptr<dolfinx::fem::Function<double>> contact_pressure, contact_active, contact_boundary;

  /// The coupled unknown (u, z, p), ghosts included, then the conduit
  /// faults' p_f (this rank's entries), for a checkpoint.
  std::span<const double> unknowns() const override;
  /// Loads unknowns() back (and u, pressure from it).
  void set_unknowns(std::span<const double> x) override;
  /// The fields of unknowns(): the displacement, the flux and the pressure.
  std::vector<UnknownsPart> parts() const override
  {
    return {{"displacement", V, _V_to_X}, {"flux", _Z, _Z_to_X}, {"pressure", Q, _Q_to_X}};
  }
  /// Sets the displacement of the state at time t (with the pressure now in
  /// `pressure`): the initial equilibrium (mechanics.initial_equilibrium).
  void set_displacement(std::span<const double> u, double t);

protected:
  /// p, u and the conduit faults' p_f (this rank's entries).
  SolveFields solve_fields() const override;

private:
  /// The right-hand side of a step to t from the state in u and pressure.
  void make_spaces(const Domain& domain, const CompiledForms& forms);
  void make_loads(const Domain& domain, const CompiledForms& forms, const Constants& constants);
  void attach_contact(const Domain& domain, const CompiledForms& forms);
  void assemble_rhs(double t);
  /// Solves the system at the right-hand side assembled; u, pressure and
  /// p_f from its solution.
  void solve_system();
  /// Iterates on the conduit faults' apertures (monolithic_conduits.h)
  /// until they settle; throws SolverError after coupling.max_iterations.
  void solve_with_conduits(double t);
  /// The conduit cells' s_n now, with a closure (empty otherwise).
  std::vector<double> fault_normal_stress();
  /// The splits of (u, z, p) for the fixed-stress preconditioner: the flow
  /// (flux and pressure), then the mechanics with its rigid-body modes.
  std::vector<Field> fields() const;

  const Problem _problem;
  const Scene& _scene;
  std::shared_ptr<const dolfinx::fem::FunctionSpace> _X, _Z;
  std::vector<std::int32_t> _V_to_X, _Z_to_X, _Q_to_X;
  std::shared_ptr<dolfinx::fem::Function<double>> _x, _u_old, _p_old;
  TimeDerivative _derivative; // of the step being solved
  BCs _bcs;
  std::vector<DisplacementValue> _bc_values;
  FluxValues _fluxes; // the prescribed normal fluxes (flux and rate boundaries)
  std::vector<WellSource> _wells;
  std::shared_ptr<dolfinx::fem::Form<double>> _a, _L_history;
  std::unique_ptr<System> _system;
  std::unique_ptr<dolfinx::la::Vector<double>> _b;
  std::unique_ptr<Loads> _loads; // body force, tractions, source, boundary pressures, gravity
  SeismicMoments _moments;
  std::unique_ptr<MonolithicConduits> _conduits;
  std::vector<double> _fault_traction; // s_n per conduit cell at the last solve (with a closure)
  mutable std::vector<double> _unknowns; // unknowns() with conduit faults
};

} // namespace biotcontact
