#include "coupling/fixed_stress.h"

#include "contact/bonds.h"
#include "coupling/contraction.h"
#include "coupling/cycle.h"
#include "coupling/pins.h"
#include "coupling/two_pass.h"
#include "coupling/window.h"
#include "time/window_control.h"

#include <algorithm>
#include <cmath>
#include <sstream>

namespace biotcontact
{
using namespace dolfinx;

double inexact_tolerance(double previous_increment)
{
  return std::clamp(1e-2 * previous_increment, iterative_tolerance, 1e-4);
}

namespace
{
using Array = std::vector<double>;

// The split's p_f, from the flow alone, can leave bonded pairs no state
// (BondFailure); the monolithic solve moves p_f with the openings.
constexpr const char* cohesive_split_advice
    = "; a cohesive fault opening along its length: coupling.scheme = \"monolithic\" solves p_f with the contact";

/// The fixed-stress split as a sequence of windows, each iterated to
/// convergence in the stages of paper section 4: flow pass (eq. 4.17-4.19),
/// mechanics pass (eq. 4.20-4.22), contraction measure (Theorems 1 and 2),
/// stopping test, next iterate, and accept or retry.
class FixedStressSplit
{
public:
  FixedStressSplit(const Problem& problem, const SplitSteps& steps, CouplingRun& run)
      : _scene(problem.scene), _coupling(*problem.scene.coupling), _parameters(problem.parameters),
        _constants(problem.constants), _flow(steps.flow), _second_pass(steps.second_pass),
        _mechanics(steps.mechanics), _measure(problem, run, steps.mechanics.space(), steps.flow.pressure_space()),
        _history(problem.scene.time_scheme, run.grid), _observer(run.observer), _report(run.report),
        _state(run.state), _grid(run.grid), _control(run.control), _V(*steps.mechanics.space()),
        _Q(*steps.flow.pressure_space()),
        _advice(split_advice(problem.materials.gamma_peak(), _coupling)),
        _rescued(_coupling.acceleration == Acceleration::automatic and problem.materials.gamma <= high_gamma)
  {
  }

  void run();

private:
  enum class Outcome { converged, not_converged, retried };

  double t(const Window& w, int m) const { return _history.t(w, m); }
  void start();
  int window_steps(int j) const;
  Window begin_window(int K, int j, int q);
  void accelerate(Window& w);
  bool stagnant(Window& w, int n);
  double tolerance(const Window& w) const;
  Outcome iterate_window(Window& w, int& n);
  bool iteration(Window& w, int n);
  void flow_pass(Window& w);
  /// Whether the flow carries conduit faults' pressures (every rank alike).
  bool conduits() const { return _flow.fault_aperture() != nullptr; }
  void mechanics_pass(Window& w);
  std::pair<double, double> stopping_test(Window& w, const Increments& inc, int n);
  void next_iterate(Window& w);
  void go_back(const Window& w, const std::string& message);
  bool retry(const Window& w, const std::string& cause);
  bool balance_accepted(const Window& w);
  bool error_accepted(const Window& w);
  bool contact_accepted(const Window& w);
  CouplingError not_converged(const Window& w);
  void accept_window(const Window& w, int n);

  const Scene& _scene;
  const CouplingSpec& _coupling;
  const Parameters& _parameters;
  const Constants& _constants;
  FlowStep& _flow;
  FlowStep* _second_pass;
  MechanicsStep& _mechanics;
  ContractionMeasure _measure;
  WindowHistory _history; // p_K, u_K and the time scheme's values before t_K
  const WindowObserver& _observer;
  CouplingReport& _report;
  ControllerState& _state;
  TimeGrid& _grid;
  StepControl* _control; // time.adaptive (q = 1), or null
  const fem::FunctionSpace& _V;
  const fem::FunctionSpace& _Q;
  const std::string _advice; // gamma and what converges instead, for not_converged
  // coupling.acceleration = "auto" acts: not above high_gamma, where G's
  // slowest modes (gamma) hide behind the rate seen, and the increments
  // bound the error no longer (docs/theory.md, "Anderson acceleration").
  const bool _rescued;
  int _attempts = 0; // retries of the current window (time.retry)
  ActiveSet _active_K; // contact active set at t_K
};

/// The converged state at the start (t = 0 or the restart's window) and the
/// scales of the stopping test: the largest p (root mean square over a
/// window's fine steps) and u of the run so far.
void FixedStressSplit::start()
{
  const int q_max = _coupling.q_auto ? _coupling.q_max : _coupling.q;
  _flow.keep_loads(q_max);
  if (_second_pass)
    _second_pass->keep_loads(q_max);
  _history.start(_flow, _mechanics.u->x()->array(), static_cast<int>(_report.fine_steps) - _state.window_q);
  _active_K = _mechanics.active_contact_set();
  if (_report.windows == 0)
  {
    _state.p_size = owned_norm(_history.p_K, _Q);
    _state.u_size = owned_norm(_history.u_K, _V);
  }
}

/// The fine steps of the window that starts at fine step j: coupling.q, or
/// with q = "auto" those of window_steps (time/window_control.h) from the
/// last window's relative change of u per unit time.
int FixedStressSplit::window_steps(int j) const
{
  if (!_coupling.q_auto)
    return _coupling.q;
  double rate = 0;
  if (_report.windows > 0)
    rate = relative(owned_norm(difference(_history.u_K, _history.u_before), _V), _state.u_size)
           / (_grid.t[j] - _grid.t[_history.j_before]);
  return biotcontact::window_steps(_grid, j, _state.q_limit, rate, _coupling.q_tolerance, _scene.stops());
}

/// The first iterate of window K (fine steps j + 1, ..., j + q): p^{0,m} =
/// p_K for all m, u^0 = u_K; with coupling.acceleration = "anderson"
/// Anderson's method from the first iteration (accelerate).
Window FixedStressSplit::begin_window(int K, int j, int q)
{
  Window w;
  w.derivative = _history.derivative(j, q);
  const bool q_changed = set_window_steps(_constants, q);
  const bool dt_changed = set_time_step(_constants, w.derivative.effective_step(_grid.dt[j]));
  if (q_changed)
    _measure.set_window_steps(q);
  for (FlowStep* flow : {&_flow, _second_pass})
    if (flow)
    {
      flow->set_time_derivative(w.derivative);
      if (dt_changed)
        flow->time_step_changed(); // all its operators, with the new q too
      else if (q_changed)
        flow->window_steps_changed();
    }
  w.K = K;
  w.j = j;
  w.q = q;
  w.w_K.assign(_flow.unknowns().begin(), _flow.unknowns().end());
  w.p_old.assign(q + 1, _history.p_K);
  w.p_new.assign(q + 1, _history.p_K);
  w.w_new.resize(q + 1);
  w.u_old = _history.u_K;
  _mechanics.begin_step(); // its u is u_K: the window's start, friction's reference
  _flow.begin_step();      // its conduit faults' pressure is the window's start
  w.fault_new.assign(q + 1, _flow.fault_pressure());
  assign(*_flow.u_window, _history.u_K);
  if (_second_pass)
    assign(*_second_pass->u_window, _history.u_K);
  if (_coupling.acceleration == Acceleration::anderson)
    accelerate(w);
  return w;
}

/// Anderson's method from here on in window w (accelerate_window).
void FixedStressSplit::accelerate(Window& w)
{
  accelerate_window(w, _V.mesh()->comm(), _coupling.depth,
                    {owned_size(_Q), owned_size(_V), _state.p_size, _state.u_size});
  w.active_set_changes = _mechanics.active_set_changes();
}

/// coupling.acceleration = "auto": whether the plain iteration of window w
/// stagnates after iteration n (coupling/cycle.h: a steady rate that would
/// not reach the tolerance in the iterations left), in which case Anderson's
/// method takes over the window, once, and the log says so.
bool FixedStressSplit::stagnant(Window& w, int n)
{
  const int left = _coupling.max_iterations - n - 1;
  if (!_rescued or w.accelerated or !stagnates(w.increments, tolerance(w), left))
    return false;
  if (_observer.note)
    _observer.note(stagnation_note(w, t(w, w.q), left));
  ++_report.accelerated_windows;
  return true;
}

/// The stopping test's tolerance of window w: coupling.tolerance, or
/// time.adaptive's for its step.
double FixedStressSplit::tolerance(const Window& w) const
{
  return _control ? iteration_tolerance(_coupling.tolerance, _scene.adaptive->tolerance, _grid.dt[w.j], t(w, w.q))
                  : _coupling.tolerance;
}

/// (a) q flow steps with u^n lagged (eq. 4.17-4.19):
///   ((S+L)(p^{n+1,m} - p^{n+1,m-1})/dt, th) + (div z^{n+1,m}, th)
///     = (Q(t_m), th) + (L (p^{n,m} - p^{n,m-1})/dt, th)
///       - ((alpha/q) div(u^n - u_K)/dt, th)
/// (with BDF2, dt / c0 and the history values of WindowHistory in place
/// of dt, p^{n+1,m-1}, p^{n,m-1} and u_K).
void FixedStressSplit::flow_pass(Window& w)
{
  if (_scene.solver.inexact_coupling)
  {
    _flow.system().set_tolerance(inexact_tolerance(w.increment));
    _mechanics.system().set_tolerance(inexact_tolerance(w.increment));
  }
  assign(*_flow.u_iterate, w.u_old);
  w.fault_old = w.fault_new;
  for (int m = 1; m <= w.q; ++m)
  {
    _history.set_time_history(_flow, w, m, w.p_new, w.u_old);
    assign(*_flow.p_iterate, w.p_old[m]);
    assign(*_flow.p_iterate_previous, _history.previous(w, w.p_old, m));
    _flow.set_fine_step(m, w.fault_new[m - 1], fault_reference(w, m));
    _flow.solve(t(w, m));
    w.p_new[m] = values(_flow.pressure->x()->array());
    std::span<const double> z_p = _flow.unknowns();
    w.w_new[m].assign(z_p.begin(), z_p.end());
    w.fault_new[m] = _flow.fault_pressure();
  }
}

/// (b) mechanics (the VI) at t_{K+1} with p = p^{n+1,q} (eq. 4.20-4.22):
/// flow.pressure holds it and is the pressure coefficient of the mechanics
/// load. (c) "multirate-two-pass": the fine steps again, without L, with
/// u^{n+1}; for q = 1 the correction would return p^A_1 itself.
void FixedStressSplit::mechanics_pass(Window& w)
{
  const long before = _mechanics.system().newton_steps();
  _mechanics.solve(t(w, w.q));
  w.newton_steps = _mechanics.system().newton_steps() - before;
  w.u_new = values(_mechanics.u->x()->array());
  if (_second_pass and w.q > 1)
    second_pass_correction(*_second_pass, _flow, w, _history);
}

/// The stopping test's increments (ContractionMeasure::stopping_increments),
/// logged; never on a stale state. With conduit faults dp is the larger of
/// the rock's and the faults' p_f increment, both logged, with the faults'
/// contraction ratio.
std::pair<double, double> FixedStressSplit::stopping_test(Window& w, const Increments& inc, int n)
{
  const bool conduits = this->conduits();
  const StoppingIncrements s = _measure.stopping_increments(w, inc, n, conduits);
  w.active = _mechanics.active_contact_set();
  _observer.record({w.K + 1, t(w, w.q), n + 1, inc.dsigma, inc.ratio, _parameters.gamma, s.dp, s.du,
                    w.active.nodes, s.fault_dp, s.fault_ratio, w.newton_steps});
  if (!std::isfinite(inc.p2) or !std::isfinite(s.du))
    // The iterates hold NaN or inf (a load or coefficient that is not
    // finite): no further iteration can recover.
    throw SolverError("non-finite values (NaN or inf) in the "
                      + std::string(std::isfinite(inc.p2) ? "displacement" : "pressure"));
  std::ostringstream entry;
  entry << " " << n + 1 << ": dp " << s.dp << " du " << s.du << " dsigma " << inc.dsigma;
  if (conduits)
    entry << " dp_f " << s.fault_dp;
  w.log.push_back(entry.str() + ";");
  return {conduits ? std::max(s.dp, s.fault_dp) : s.dp, s.du};
}

/// The iterate the next flow pass reads: the map value (p^{n+1}, u^{n+1}),
/// or with Anderson a combination of the last map values. The differences
/// of earlier iterations describe the map of their contact active set
/// only: a new set restarts the history (too many, Anderson itself).
void FixedStressSplit::next_iterate(Window& w)
{
  if (const long changes = _mechanics.active_set_changes(); w.anderson and changes != w.active_set_changes)
  {
    w.active_set_changes = changes;
    if (!w.anderson->restart()) // the map kept changing: the plain iteration from here (anderson.h)
      w.anderson.reset();
  }
  if (w.anderson)
    return mix_iterates(w);
  w.p_old = w.p_new;
  w.u_old = w.u_new;
}

/// One coupling iteration n of window w; true when it converged.
bool FixedStressSplit::iteration(Window& w, int n)
{
  flow_pass(w);
  mechanics_pass(w);
  const Increments inc = _measure.measure(w, n);
  _measure.hold_against_gamma(w, inc, n);
  const auto [dp_norm, du_norm] = stopping_test(w, inc, n);
  next_iterate(w);
  if (_observer.iteration)
    _observer.iteration(w.K + 1, n + 1, dp_norm, du_norm);
  w.increment = std::max(dp_norm, du_norm);
  w.active_nodes.push_back(w.active.nodes);
  record_flags(w);
  w.increments.push_back(w.increment);
  const double tolerance = this->tolerance(w);
  const bool converged = dp_norm <= tolerance and du_norm <= tolerance;
  if (converged)
  {
    _measure.record_coupled_residual(w, inc, _history, tolerance);
    // Compared once per window, on the converged iterate (one collective).
    w.contact_changed = !same_active_set(w.active, _active_K, _V.mesh()->comm());
  }
  return converged;
}

/// Iterates window w to convergence (n ends as the last iteration's index).
FixedStressSplit::Outcome FixedStressSplit::iterate_window(Window& w, int& n)
{
  try
  {
    const PinnedSteps pinned{_mechanics, _flow, _V.mesh()->comm(), _coupling.pin_cycles,
                             _observer.note, window_name(w, t(w, w.q))};
    release_pins(w, pinned);
    for (n = 0; n < _coupling.max_iterations; ++n)
    {
      if (iteration(w, n) and pins_consistent(w, n, pinned))
        return Outcome::converged;
      if (stagnant(w, n))
        accelerate(w);
      // A cycle goes on to max_iterations: end it here, unless pins end it.
      if ((w.cycle = cycle_period(w.active_nodes, w.increments)) > 0 and !pin_cycle(w, n, pinned))
        return Outcome::not_converged;
    }
  }
  catch (const SolverError& e)
  {
    // The failing solve named its system; the iteration is known here.
    std::string cause = "coupling iteration " + std::to_string(n + 1) + ": " + e.what();
    if (dynamic_cast<const BondFailure*>(&e))
      cause += cohesive_split_advice;
    if (!retry(w, cause))
      throw SolverError(cause);
    return Outcome::retried;
  }
  return Outcome::not_converged;
}

/// Back to the start of window w, to be computed again (`message` says why
/// and on which steps).
void FixedStressSplit::go_back(const Window& w, const std::string& message)
{
  _flow.set_unknowns(w.w_K);
  assign(*_mechanics.u, _history.u_K);
  if (_observer.retry)
    _observer.retry(message);
}

/// time.retry: back to the start of the window, whose fine steps are
/// halved (two windows of q steps); false when no retry is left.
bool FixedStressSplit::retry(const Window& w, const std::string& cause)
{
  const auto message = retry_step(_scene, {w.K + 1, cause, w.j, w.q}, _attempts, _report.retries, _grid);
  if (!message)
    return false;
  go_back(w, *message);
  return true;
}

/// Whether every fine step of the converged window w conserves what it
/// must (FlowStep::unbalanced: a conduit fault's volumes); if one does
/// not, back to the window's start on halved steps (time.retry), or the
/// run ends with the step and the fault named.
bool FixedStressSplit::balance_accepted(const Window& w)
{
  for (int m = 1; m <= w.q and conduits(); ++m)
  {
    _flow.set_unknowns(w.w_new[m]);
    _flow.set_fine_step(m, w.fault_new[m - 1], w.fault_new[m]);
    const std::string failure = _flow.unbalanced(t(w, m));
    if (failure.empty())
      continue;
    const std::string message = window_name(w, t(w, m)) + ": " + failure;
    if (retry(w, message))
      return false;
    _report.mean_contraction_ratio = _report.ratios ? _state.ratio_sum / _report.ratios : 0.0;
    throw CouplingError(message);
  }
  return true;
}

/// time.adaptive: whether the converged window's error estimate accepts it
/// (the control then plans the next steps; a window in which the active
/// contact set changed is accepted unestimated); if not, back to its start,
/// to be computed again on the shorter steps the control planned.
bool FixedStressSplit::error_accepted(const Window& w)
{
  if (!_control)
    return true;
  std::string message;
  if (_control->judge({w.j + w.q, w.p_new[w.q], w.u_new, !w.contact_changed}, _grid, _report.adaptive,
                      _state.adaptive, message))
    return true;
  go_back(w, message);
  return false;
}

/// coupling.q = "auto": a window of q > 1 fine steps in which the contact
/// active set changed is computed again with q = 1 (the
/// mechanics would have seen the change only at the window's end); the
/// windows then grow again from q = 1 (window_limit). Accepted otherwise.
bool FixedStressSplit::contact_accepted(const Window& w)
{
  if (!_coupling.q_auto or w.q == 1 or !w.contact_changed)
    return true;
  ++_report.q_rejections;
  _state.q_limit = 1;
  std::ostringstream message;
  message << "step " << w.K + 1 << ": the contact active set changed (" << _active_K.nodes << " -> "
          << w.active.nodes << " nodes) in a window of q = " << w.q << "; again with q = 1";
  go_back(w, message.str());
  return false;
}

/// The error of a window that did not converge in coupling.max_iterations
/// or cycled (coupling/cycle.h), with the last increments.
CouplingError FixedStressSplit::not_converged(const Window& w)
{
  const bool propose_retry = _scene.retry == 0 and _scene.has_contact();
  return CouplingError(not_converged_message(w, {t(w, w.q), _coupling.max_iterations, _advice, propose_retry}));
}

/// Accept the window: write every fine flow step, then the mechanics step;
/// its end state is the next window's start.
void FixedStressSplit::accept_window(const Window& w, int n)
{
  _attempts = 0;
  _report.pinned_windows += w.pin_rounds > 0;
  for (int m = 1; m <= w.q; ++m)
  {
    _flow.set_unknowns(w.w_new[m]);
    _flow.set_fine_step(m, w.fault_new[m - 1], w.fault_new[m]);
    _flow.accept(t(w, m));
    _observer.flow_state(t(w, m));
  }
  _state.q_limit = window_limit(w.q, _coupling.q_max, w.contact_changed);
  _active_K = w.active;
  _report.windows = w.K + 1;
  _report.fine_steps = w.j + w.q;
  _state.window_q = w.q;
  _report.max_window_q = std::max(_report.max_window_q, w.q);
  _mechanics.accept(t(w, w.q));
  _observer.mechanics_state(t(w, w.q), w.K + 1, n + 1);
  _history.accept(w, _flow);
}

void FixedStressSplit::run()
{
  start();
  for (int K = _report.windows, j = static_cast<int>(_report.fine_steps); j < _grid.steps(); ++K)
  {
    Window w = begin_window(K, j, window_steps(j));
    int n = 0;
    const Outcome outcome = iterate_window(w, n);
    if (outcome != Outcome::retried)
    {
      const int iterations = std::min(n + 1, _coupling.max_iterations);
      _report.coupling_iterations += iterations;
      _report.max_iterations_per_step = std::max(_report.max_iterations_per_step, iterations);
    }
    if (outcome == Outcome::not_converged
        and !retry(w, w.cycle ? "the fixed-stress split cycles" : "the fixed-stress split did not converge"))
    {
      _report.mean_contraction_ratio = _report.ratios ? _state.ratio_sum / _report.ratios : 0.0;
      throw not_converged(w);
    }
    if (outcome != Outcome::converged or !balance_accepted(w) or !error_accepted(w) or !contact_accepted(w))
    {
      K = w.K - 1; // the same window again, on the shorter steps or with q = 1
      continue;
    }
    accept_window(w, n);
    j = w.j + w.q;
    if (_observer.stop and _observer.stop())
      break;
  }
  _report.mean_contraction_ratio = _report.ratios ? _state.ratio_sum / _report.ratios : 0.0;
}

} // namespace

void run_fixed_stress(const Problem& problem, const SplitSteps& steps, CouplingRun& run)
{
  FixedStressSplit(problem, steps, run).run();
}

} // namespace biotcontact
