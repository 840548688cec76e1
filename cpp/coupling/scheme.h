// The scheme of a run: the steps a scene needs (each scene allocates only
// the physics it has) and the loop that drives them, the fixed-stress split
// or one solve per step, chosen once from the scene.
#pragma once

#include "assembly/problem.h"
#include "coupling/coupling.h"
#include "time/step_control.h"
#include "steps/flow_step.h"
#include "steps/mechanics_step.h"
#include "steps/monolithic_step.h"

#include <functional>
#include <memory>
#include <vector>

namespace biotcontact
{

/// @brief The steps of a run and the scheme that drives them; the fields
/// output and diagnostics read, whichever step produced them.
///
/// The split ("single-rate", "multirate", "multirate-two-pass") has a flow
/// and a mechanics step (and the second pass's flow step); "monolithic" one
/// coupled step; a scene with one physics its one step.
class Scheme
{
public:
  explicit Scheme(const Problem& problem);
  Scheme(const Scheme&) = delete;
  Scheme& operator=(const Scheme&) = delete;

  /// Drives the steps from the end of run.report.windows to the end time:
  /// the split's flow and mechanics steps (coupling/fixed_stress.h), or one
  /// solve per step of the one step, monolithic or a single physics'
  /// (coupling/single_solve.h).
  void run(CouplingRun& run);

  /// time.adaptive's scales from the state at t = 0 (nothing without it).
  void start(ControllerState& state);
  /// `told(system, iteration)` after each Newton step of a contact solve.
  void on_newton_step(const std::function<void(const std::string&, int)>& told);

  /// The steps, in the order of summary.json.
  const std::vector<Step*>& steps() const { return _steps; }
  /// The time scheme's and time.adaptive's memory, by checkpoint name.
  History history() const;
  /// Assembly time of the steps' loads and matrices.
  double assembly_time() const;

  std::shared_ptr<const dolfinx::fem::FunctionSpace> V; // displacement space (null without mechanics)
  std::shared_ptr<dolfinx::fem::Function<double>> u, p, contact_pressure, contact_active, contact_boundary;
  /// The pore pressure mechanics.pore_pressure gives (one-way coupling),
  /// null otherwise: sigma_v's pressure where there is no flow.
  std::shared_ptr<const dolfinx::fem::Function<double>> given_pressure;
  std::unique_ptr<StepControl> step_control; // time.adaptive

  // What output and diagnostics read, asked of the step that owns it: the
  // monolithic step, else the split's (or a single physics') flow or
  // mechanics step.

  /// The flux into `out` (FlowStep::flux or MonolithicStep::flux; nothing
  /// without flow).
  void flux(dolfinx::fem::Function<double>& out) const;
  /// The conduit faults' cell fields at t (FlowStep::fault_flow or
  /// MonolithicStep::fault_flow; empty without flow).
  std::vector<double> fault_flow(double t) const;
  /// The faults' seismic moments step by step (MechanicsStep's or
  /// MonolithicStep's seismic_moments; none without mechanics).
  SeismicMoments seismic_moments() const;
  /// The conduit faults' volumes since the run's start
  /// (FlowStep::fault_volumes or MonolithicStep::fault_volumes; none without
  /// flow).
  std::vector<std::pair<std::string, FaultVolumes>> fault_volumes() const;
  /// Where the conduit faults meet, and the rates through (FlowStep's or
  /// MonolithicStep's fault_intersections; none without conduit faults).
  std::vector<IntersectionRate> fault_intersections() const;
  /// The contact's state (MechanicsStep::contact_state or
  /// MonolithicStep::contact_state; empty when the step has no contact).
  ContactState contact_state();

private:
  void make_monolithic(const Problem& problem);
  void make_split(const Problem& problem);
  template <class S>
  void take_contact_fields(S& step);

  const Problem& _problem;
  Materials _unstabilised; // the second pass's: L = 0
  std::unique_ptr<FlowStep> _flow, _second_pass;
  std::unique_ptr<MechanicsStep> _mechanics;
  std::unique_ptr<MonolithicStep> _monolithic;
  std::vector<Step*> _steps;
};

} // namespace biotcontact
