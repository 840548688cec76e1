// One flow step in mixed form, RT0 flux x P0 pressure (alg. "Flow"), backward
// Euler in form (BDF2 enters through the step dt/c0 and the history values of
// time/time_scheme.h), with the fixed-stress terms of alg. "Single-rate ... (a)" and
// "Multirate ... (a)" when the scene is coupled.
#pragma once

#include "assembly/fault_aperture.h"
#include "assembly/fault_flow.h"
#include "assembly/wells.h"
#include "domain/domain.h"
#include "assembly/forms.h"
#include "assembly/linear_algebra.h"
#include "assembly/loads.h"
#include "assembly/materials.h"
#include "assembly/parameters.h"
#include "assembly/problem.h"
#include "steps/step.h"
#include "steps/system.h"

#include <dolfinx/fem/Form.h>
#include <dolfinx/fem/Function.h>
#include <algorithm>
#include <deque>
#include <memory>
#include <optional>

namespace biotcontact
{

/// The flow step's place in a scheme: the flow of every scheme, or the
/// second pass of "multirate-two-pass" (L = 0 in its problem's materials:
/// no stabilisation term; its time history is set by the split).
enum class FlowPass
{
  first,
  second
};

/// @brief The flow step: Darcy's law and mass balance in mixed form
/// (RT0 x P0), with the fixed-stress terms of a coupled scene.
class FlowStep : public Step
{
public:
  /// `V` is the displacement space of a coupled scene, null otherwise.
  FlowStep(const Problem& problem, std::shared_ptr<const dolfinx::fem::FunctionSpace> V,
           FlowPass pass = FlowPass::first);

  /// Solves for (z, p) at time t from the current coupling data below;
  /// leaves p in `pressure`.
  void solve(double t);

  /// One solve per step: the pressure history of `d` from the last step's
  /// pressure and p_before, then solve(t).
  void advance(double t, const TimeDerivative& d) override;

  std::string name() const override { return _pass == FlowPass::first ? "flow" : "flow_second_pass"; }
  StepState state() const override;
  void restore(const StepState& start) override { set_unknowns(start.unknowns); }
  /// ConduitFaults::pin_flipped, turn_contradicted_pins, turn_pins and
  /// release_pins (none without conduit faults).
  int pin_flipped() { return *_conduits ? _conduits->pin_flipped() : 0; }
  bool turn_contradicted_pins() { return *_conduits and _conduits->turn_contradicted_pins(); }
  void turn_pins()
  {
    if (*_conduits)
      _conduits->turn_pins();
  }
  void release_pins()
  {
    if (*_conduits)
      _conduits->release_pins();
  }
  /// The conduit faults' pressure now is p_f^old of every solve of the
  /// step (the split's iterations re-solve it); their iterates' open cells
  /// start anew.
  void begin_step() override
  {
    _fault_pressure_previous = _fault_pressure;
    _conduits->begin_step();
  }
  /// p_before takes the accepted step's start pressure.
  void keep_history(const StepState& start) override;
  /// The conduit faults' volumes take the accepted step to t.
  void accept(double t) override;
  /// A conduit fault whose volumes the step to t would leave unbalanced
  /// (ConduitFaults::unbalanced), or empty.
  std::string unbalanced(double t) const override;
  /// BDF2: p_before, u_before, u_path_before (u_before with coupling.q =
  /// "auto" too: the last window's change of u); none for the second pass.
  History history() const override;
  std::span<const double> pressure_values() const override { return pressure->x()->array(); }

  /// The mixed solution (z, p) of the last solve, and after it the conduit
  /// faults' pressure (a copy then); and its restoration (the multirate
  /// scheme keeps one per fine step for output).
  std::span<const double> unknowns() const override;
  void set_unknowns(std::span<const double> w) override;
  /// The fields of unknowns(): the flux and the pressure (none for the
  /// second pass, which every window computes anew: a checkpoint keeps
  /// nothing of it).
  /// The conduit faults' pressure, "fault_pressure" (every rank's copy),
  /// their volumes, "fault_volumes" (4 per fault), and their hydraulic
  /// apertures at the step's start, "fault_apertures".
  std::map<std::string, std::vector<double>> arrays() const override;
  void restore_arrays(const std::map<std::string, std::vector<double>>& arrays) override;
  std::vector<UnknownsPart> parts() const override
  {
    if (_pass == FlowPass::second)
      return {};
    return {{"flux", _Z, _Z_to_W}, {"pressure", _Q, _Q_to_W}};
  }

  /// Writes the cell averages of the flux z into a DG0 vector field.
  void flux(dolfinx::fem::Function<double>& out) const;

  /// The conduit faults' openings as a map of the displacement and the
  /// load of their pressure on the faces (a coupled scene with conduit
  /// faults; null otherwise), and that pressure (this rank's entries).
  const FaultAperture* fault_aperture() const { return _aperture.get(); }
  const std::vector<double>& fault_pressure() const { return _fault_pressure; }
  /// The next solve (or accept) is fine step m of its window (1 for the
  /// single-rate split), its conduit faults' p_f^old `previous`, p_f^{n+1,m-1}
  /// (this rank's entries), and `iterate` the reference of their fixed-stress
  /// term, p_f^{n,m} - p_f^{n,m-1} + p_f^{n+1,m-1} (p_f^n when q = 1), the
  /// fine-step form of the rock's L (p^{n,m} - p^{n,m-1}) (paper eq. 4.17).
  /// The apertures are read at fine step 1 only: the mechanics iterate is
  /// the window's.
  void set_fine_step(int m, std::span<const double> previous, std::span<const double> iterate);
  /// The time derivative of the split's steps (advance sets its own): the
  /// conduit faults' storage differentiates with it as the rock's.
  void set_time_derivative(const TimeDerivative& d) { _derivative = d; }
  /// The conduit cells' effective normal stress s_n at the last mechanics
  /// solve (MechanicsStep::fault_traction), which their closure follows.
  void read_fault_traction(const std::vector<double>& s_n) { _fault_traction = &s_n; }
  /// The conduit faults' hydraulic apertures at the window's start are
  /// `first`'s (the second pass of "multirate-two-pass", which accepts no
  /// step of its own).
  void take_start_apertures(const FlowStep& first)
  {
    _conduits->set_start_apertures(first._conduits->start_apertures());
  }

  /// The conduit faults' cell fields at time t on rank 0
  /// (ConduitFaults::cell_values; empty without conduit faults; collective).
  std::vector<double> fault_flow(double t) const;
  /// The conduit faults' volumes since the run's start (every rank; none
  /// without conduit faults).
  std::vector<std::pair<std::string, FaultVolumes>> fault_volumes() const { return _conduits->volumes(); }
  /// Where the conduit faults meet, and the rates through (every rank).
  std::vector<IntersectionRate> fault_intersections() const { return _conduits->intersection_rates(); }

  /// Keeps the loads of the last `times` solve times (q for a multirate
  /// window, whose iterations revisit its fine times; 1 by default).
  void keep_loads(int times) { _loads->keep(times); }

  /// The matrix depends on dt: reassembled (and refactorised at the next
  /// solve) after set_time_step changed the "dt" constant.
  void time_step_changed() override;

  /// Only the displacement term, alpha/(q dt) div, depends on q: reassembled
  /// after set_window_steps changed the "q" constant (no refactorisation).
  void window_steps_changed();

  std::shared_ptr<const dolfinx::fem::FunctionSpace> pressure_space() const { return _Q; }

  // The unknown of the last solve.
  std::shared_ptr<dolfinx::fem::Function<double>> pressure;
  // Coupling data of the right-hand side (alg. multirate (a); q = 1 is the
  // single-rate step): p^{n+1,m-1}, p^{n,m}, p^{n,m-1}, u^n, u_K.
  std::shared_ptr<dolfinx::fem::Function<double>> p_previous, p_iterate, p_iterate_previous;
  std::shared_ptr<dolfinx::fem::Function<double>> u_iterate, u_window;
  // The accumulation's memory for time.scheme = "bdf2" (time/time_scheme.h):
  // the pressure one fine step and the displacement one window before the
  // current window's start, and the multirate displacement path's value one
  // fine step before it (u_* null without mechanics); checkpointed.
  std::shared_ptr<dolfinx::fem::Function<double>> p_before, u_before, u_path_before;

  const System& system() const override { return *_system; }
  System& system() override { return *_system; }

protected:
  /// p, and the conduit faults' p_f (this rank's entries).
  SolveFields solve_fields() const override
  {
    const auto n = static_cast<std::int32_t>(_fault_pressure.size());
    return {{pressure->x()->array(), owned_size(*_Q), true}, {}, {_fault_pressure, n, bool(*_conduits)},
            _Q->mesh()->comm()};
  }

private:
  void make_spaces(const Domain& domain, const CompiledForms& forms,
                   std::shared_ptr<const dolfinx::fem::FunctionSpace> V);
  void make_loads(const Domain& domain, const CompiledForms& forms, const Constants& constants);
  template <class Make>
  void make_coupling_operators(const CompiledForms& forms, const Make& make,
                               std::shared_ptr<const dolfinx::fem::FunctionSpace> V, double L);
  /// The flux and pressure DOFs of W: the splits of an iterative solve.
  std::vector<Field> fields() const;
  /// The conduit faults' pressure p_f (assembly/fault_flow.h), appended to
  /// the system, starting from the initial pressure at the cells'
  /// centroids (nothing without conduit faults).
  void make_conduits(const Domain& domain, const FacetFlux& flux, std::shared_ptr<const dolfinx::fem::FunctionSpace> V);
  /// The conduits' hydraulic apertures from the displacement now (u_K) and
  /// the normal stress of their closure, their rows appended again if they
  /// changed.
  void update_apertures();
  /// The conduit faults' rows at the current dt, into the system.
  void append_conduits();

  const Scene& _scene;
  const FlowPass _pass;
  std::shared_ptr<const dolfinx::fem::FunctionSpace> _W, _Q, _Z;
  std::vector<std::int32_t> _Q_to_W, _Z_to_W;
  std::shared_ptr<dolfinx::fem::Function<double>> _w;
  BCs _bcs;
  FluxValues _fluxes; // the prescribed normal fluxes (flux and rate boundaries)
  std::vector<WellSource> _wells;
  std::shared_ptr<dolfinx::fem::Form<double>> _a, _a_storage, _a_stabilisation, _a_displacement;
  // Operators of the coupling terms (W x Q, W x Q, W x V) and work vectors.
  std::optional<dolfinx::la::petsc::Matrix> _storage, _stabilisation, _displacement;
  std::unique_ptr<dolfinx::la::Vector<double>> _dp, _du;
  std::unique_ptr<System> _system;
  std::unique_ptr<dolfinx::la::Vector<double>> _b;
  std::unique_ptr<Loads> _loads; // source, boundary pressures, gravity
  const Constants& _constants;
  std::unique_ptr<ConduitFaults> _conduits;
  std::unique_ptr<FaultAperture> _aperture;
  std::vector<double> _fault_pressure, _fault_pressure_previous; // p_f (this rank's entries), and one step before
  const std::vector<double>* _fault_traction = nullptr;          // s_n per conduit cell (every rank)
  int _fine_step = 1; // of the window, set_fine_step
  TimeDerivative _derivative; // of the step (advance, set_time_derivative)
  /// The fine step of the next solve or accept, ending at t.
  FineStep fine_step(double t) const;
  mutable std::vector<double> _unknowns; // unknowns() with conduit faults
};

} // namespace biotcontact
