#include "coupling/fixed_stress.h"

#include "coupling/anderson.h"
#include "time/window_control.h"
#include "time/time_scheme.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <sstream>

namespace biotcontact
{
using namespace dolfinx;

namespace
{
using Array = std::vector<double>;

Array difference(const Array& a, const Array& b)
{
  Array d(a.size());
  for (std::size_t i = 0; i < a.size(); ++i)
    d[i] = a[i] - b[i];
  return d;
}

/// Ratios measured below this fraction of a window's first ||delta sigma||
/// are at round-off level (see the loop).
constexpr double resolved_fraction = 1e-6;
constexpr double round_off_fraction = 1e-9;

/// increment / size, or the increment itself while size = 0.
double relative(double increment, double size) { return size > 0 ? increment / size : increment; }

/// Changes of the contact active set so far (0 without contact).
long contact_changes(MechanicsStep& mechanics)
{
  return mechanics.system().has_contact() ? mechanics.system().contact().active_set_changes() : 0;
}

} // namespace

double inexact_tolerance(double previous_increment)
{
  return std::clamp(1e-2 * previous_increment, iterative_tolerance, 1e-4);
}

namespace
{

/// One window's iterates: p^{n,m} and p^{n+1,m} (m = 0..q; m = 0 is p_K),
/// u^n and u^{n+1}, the mixed states (z, p)^{n+1,m}, and what the
/// contraction measure and the error message carry from one iteration to
/// the next.
struct Window
{
  int K = 0;                           // the window [t_K, t_{K+1}]
  int j = 0, q = 1;                    // its first fine step and its fine steps: t_K = t_j, t_{K+1} = t_{j+q}
  ActiveSet active;                    // contact active set of u^{n+1} (the last iteration's)
  bool contact_changed = false;        // converged active != the set at t_K
  TimeDerivative derivative;           // of every fine step (time_scheme.h)
  std::vector<double> w_K;             // flow state (z, p) at t_K, for a retry
  std::vector<Array> p_old, p_new, w_new;
  Array u_old, u_new;
  // The conduit faults' p_f^{n,m} and p_f^{n+1,m} (m = 0..q, the last rank's).
  std::vector<Array> fault_old, fault_new;
  std::optional<AndersonAcceleration> anderson;
  long active_set_changes = 0;         // at the last Anderson restart
  double dsigma_previous = std::numeric_limits<double>::quiet_NaN(), dsigma_first = 0;
  double fault_previous = std::numeric_limits<double>::quiet_NaN(); // ||dp_f|| of the last iteration
  long newton_steps = 0; // of the last mechanics pass's contact solve
  double increment = 1;                // max(dp, du) of the last iteration
  std::vector<std::string> log;        // the last iterations, for the error message
};

/// What one coupling iteration measured on its increments.
struct Increments
{
  Array du;
  double dsigma = 0;   // ||delta sigma|| of Theorem 1 (q = 1) or 2 (multirate)
  double theorem2 = 0; // Theorem 2's quantity (NaN without L)
  double residual = 0; // L times it, cell by cell (ContractionNorm::Quantity::coupled_residual)
  double ratio = 0;    // dsigma / the previous iteration's (NaN at n = 0)
  double dp2 = 0, p2 = 0;
  double fault_dp = 0, fault_p = 0; // ||dp_f|| and ||p_f|| (l2 over the conduit cells; 0 without)
};

/// The fixed-stress split as a sequence of windows, each iterated to
/// convergence in the stages of paper section 4: flow pass (eq. 4.17-4.19),
/// mechanics pass (eq. 4.20-4.22), contraction measure (Theorems 1 and 2),
/// stopping test, next iterate, and accept or retry.
class FixedStressSplit
{
public:
  FixedStressSplit(const Problem& problem, const SplitSteps& steps, CouplingRun& run)
      : _scene(problem.scene), _coupling(*problem.scene.coupling), _parameters(problem.parameters),
        _constants(problem.constants), _stabilised(problem.materials.max_L > 0), _flow(steps.flow),
        _second_pass(steps.second_pass), _mechanics(steps.mechanics),
        _contraction(problem.forms, problem.materials, problem.parameters.q, steps.mechanics.space(),
                     steps.flow.pressure_space()),
        _observer(run.observer), _report(run.report), _state(run.state), _grid(run.grid), _control(run.control),
        _V(*steps.mechanics.space()), _Q(*steps.flow.pressure_space()),
        _accelerated(_coupling.acceleration == Acceleration::anderson),
        _advice(split_advice(problem.materials.gamma_peak(), _coupling.acceleration))
  {
  }

  void run();

private:
  enum class Outcome
  {
    converged,
    not_converged,
    retried
  };

  /// Fine time m of window w (t_K + m dt for a constant step).
  double t(const Window& w, int m) const { return _grid.t[w.j + m]; }
  void start();
  int window_steps(int j) const;
  Window begin_window(int K, int j, int q);
  Outcome iterate_window(Window& w, int& n);
  bool iteration(Window& w, int n);
  TimeDerivative window_derivative(int j, int q) const;
  Array path(const Window& w, const Array& u, int m) const;
  void set_time_history(FlowStep& flow, const Window& w, int m, const std::vector<Array>& p,
                        const Array& u) const;
  void flow_pass(Window& w);
  Array fault_reference(const Window& w, int m) const;
  /// Whether the flow carries conduit faults' pressures (every rank alike).
  bool conduits() const { return _flow.fault_aperture() != nullptr; }
  void mechanics_pass(Window& w);
  void second_pass_correction(Window& w);
  Increments measure_contraction(const Window& w, int n) const;
  void hold_against_gamma(Window& w, const Increments& inc, int n);
  std::pair<double, double> stopping_test(Window& w, const Increments& inc, int n);
  double stopping_tolerance(const Window& w) const;
  void next_iterate(Window& w);
  void record_coupled_residual(const Window& w, const Increments& inc);
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
  const bool _stabilised; // L > 0 in some cell: Theorem 2's quantity is measured
  FlowStep& _flow;
  FlowStep* _second_pass;
  MechanicsStep& _mechanics;
  mutable ContractionNorm _contraction; // its work vectors change as it measures
  const WindowObserver& _observer;
  CouplingReport& _report;
  ControllerState& _state;
  TimeGrid& _grid;
  StepControl* _control; // time.adaptive (q = 1), or null
  const fem::FunctionSpace& _V;
  const fem::FunctionSpace& _Q;
  const bool _accelerated;
  const std::string _advice; // gamma and what converges instead, for not_converged
  Array _p_K, _u_K; // the converged state at t_K
  // For BDF2: the pressure one fine step and the displacement one window
  // before t_K, and the displacement path's value one fine step before t_K.
  Array _p_before, _u_before, _u_path_before;
  int _j_before = 0;  // the previous window's first fine step (t_{K-1})
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
  _p_K = values(_flow.pressure->x()->array());
  _u_K = values(_mechanics.u->x()->array());
  _p_before = values(_flow.p_before->x()->array()); // restored by a restart
  _u_before = values(_flow.u_before->x()->array());
  _u_path_before = values(_flow.u_path_before->x()->array());
  _j_before = static_cast<int>(_report.fine_steps) - _state.window_q;
  _active_K = _mechanics.active_contact_set();
  if (_report.windows == 0)
  {
    _state.p_size = owned_norm(_p_K, _Q);
    _state.u_size = owned_norm(_u_K, _V);
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
    rate = relative(owned_norm(difference(_u_K, _u_before), _V), _state.u_size)
           / (_grid.t[j] - _grid.t[_j_before]);
  return biotcontact::window_steps(_grid, j, _state.q_limit, rate, _coupling.q_tolerance, _scene.stops());
}

/// The first iterate of window K (fine steps j + 1, ..., j + q): p^{0,m} =
/// p_K for all m, u^0 = u_K; with coupling.acceleration = "anderson" the
/// Anderson state (p^1, ..., p^q, u), weighted by the scales of the
/// stopping test (coupling/anderson.h).
Window FixedStressSplit::begin_window(int K, int j, int q)
{
  Window w;
  w.derivative = window_derivative(j, q);
  const bool q_changed = set_window_steps(_constants, q);
  const bool dt_changed = set_time_step(_constants, w.derivative.effective_step(_grid.dt[j]));
  if (q_changed)
    _contraction.set_window_steps(q);
  for (FlowStep* flow : {&_flow, _second_pass})
    if (flow and dt_changed)
      flow->time_step_changed(); // all its operators, with the new q too
    else if (flow and q_changed)
      flow->window_steps_changed();
  w.K = K;
  w.j = j;
  w.q = q;
  w.w_K.assign(_flow.unknowns().begin(), _flow.unknowns().end());
  w.p_old.assign(q + 1, _p_K);
  w.p_new.assign(q + 1, _p_K);
  w.w_new.resize(q + 1);
  w.u_old = _u_K;
  _mechanics.begin_step(); // its u is u_K: the window's start, friction's reference
  _flow.begin_step();      // its conduit faults' pressure is the window's start
  w.fault_new.assign(q + 1, _flow.fault_pressure());
  assign(*_flow.u_window, _u_K);
  if (_second_pass)
    assign(*_second_pass->u_window, _u_K);
  w.active_set_changes = contact_changes(_mechanics);
  if (_accelerated)
  {
    std::vector<std::int32_t> owned(q, owned_size(_Q));
    owned.push_back(owned_size(_V));
    // p_size is a fine step's: the window's q pressures weigh as one field.
    const double p_size = std::sqrt(static_cast<double>(q)) * _state.p_size;
    std::vector<double> weights(q, p_size > 0 ? 1 / p_size : 1.0);
    weights.push_back(_state.u_size > 0 ? 1 / _state.u_size : 1.0);
    w.anderson.emplace(_V.mesh()->comm(), _coupling.depth, owned, weights);
  }
  return w;
}

/// The time derivative of window K's fine steps: time.scheme's, from the
/// steps before (time_scheme.h). With q > 1 every fine step of a window
/// shares one matrix, so BDF2 needs the step before the window to equal the
/// window's fine step (w = 1); the first window, and one whose fine step
/// a retry halved, take backward Euler, which keeps the global error second
/// order (a bounded number of first-order steps, each O(dt^2)).
TimeDerivative FixedStressSplit::window_derivative(int j, int q) const
{
  const double dt = _grid.dt[j], previous = j > 0 ? _grid.dt[j - 1] : 0.0;
  if (q > 1 and previous != dt)
    return {};
  return time_derivative(_scene.time_scheme, dt, previous);
}

/// The displacement of window w at its fine time m (m = 0..q) along the
/// window's path from u_K to u = u(t_{K+1}). Backward Euler: the paper's
/// straight line. BDF2: the quadratic through u_{K-1}, u_K, u
///   Q(t_K + s) = u_K + s D1 + s (s - H) D2,  D1 = (u - u_K)/H,
///   D2 = ((u - u_K)/H - (u_K - u_{K-1})/H1) / (H + H1),
/// H and H1 the window's and the previous window's lengths: the straight
/// line (D2 = 0) makes the flow's displacement term first order in H
/// whatever the time scheme, the quadratic keeps it second order. The
/// first window has no u_{K-1}, and u_0 may be the state before a load
/// applied at t = 0+: there u takes its end value at the first fine step
/// (the undrained response at once; the straight line would spread a jump
/// over the window and drain too little, an O(H) error), and with q > 1 the
/// second window, whose u_{K-1} is u_0, keeps the straight line
/// (docs/theory.md, "Time schemes").
Array FixedStressSplit::path(const Window& w, const Array& u, int m) const
{
  const bool bdf2 = _scene.time_scheme == TimeScheme::bdf2;
  if (bdf2 and w.K == 0)
    return m == 0 ? _u_K : u;
  const double H = t(w, w.q) - t(w, 0), s = t(w, m) - t(w, 0);
  const bool quadratic = bdf2 and (w.q == 1 or w.K > 1);
  const double H1 = quadratic ? t(w, 0) - _grid.t[_j_before] : 1.0;
  Array Q(u.size());
  for (std::size_t i = 0; i < u.size(); ++i)
  {
    const double D1 = (u[i] - _u_K[i]) / H;
    const double D2 = quadratic ? (D1 - (_u_K[i] - _u_before[i]) / H1) / (H + H1) : 0.0;
    Q[i] = _u_K[i] + s * D1 + s * (s - H) * D2;
  }
  return Q;
}

/// The time history of fine step m of `flow` from the pressures p[0..m-1]
/// (p[0] = p_K) and the window's displacement u. Backward Euler: p[m-1] and
/// u_K (the paper's scheme). BDF2 differentiates the fluid content
/// S p + alpha div u at the fine times with the window's derivative (BDF2,
/// or backward Euler where it starts), p from its fine steps and u along
/// the window's path:
///   p* = (c1 p[m-1] - c2 p[m-2]) / c0,
///   alpha div(u - u_window) / (q dt / c0)
///     = alpha div (c0 Q(t_m) - c1 Q(t_{m-1}) + c2 Q(t_{m-2})) / dt,
/// i.e. u_window = u - q (Q(t_m) - Q*), where the values one fine step
/// before t_K (p[-1], Q(t_{-1})) are those of the previous window.
void FixedStressSplit::set_time_history(FlowStep& flow, const Window& w, int m, const std::vector<Array>& p,
                                        const Array& u) const
{
  if (_scene.time_scheme != TimeScheme::bdf2)
  {
    assign(*flow.p_previous, p[m - 1]);
    return;
  }
  const TimeDerivative& d = w.derivative;
  assign(*flow.p_previous, history_value(d, p[m - 1], m >= 2 ? p[m - 2] : _p_before));
  const Array Q = path(w, u, m);
  const Array Q_star = history_value(d, path(w, u, m - 1), m >= 2 ? path(w, u, m - 2) : _u_path_before);
  std::span<double> window = flow.u_window->x()->mutable_array();
  for (std::size_t i = 0; i < Q.size(); ++i)
    window[i] = u[i] - w.q * (Q[i] - Q_star[i]);
}

/// (a) q flow steps with u^n lagged (eq. 4.17-4.19):
///   ((S+L)(p^{n+1,m} - p^{n+1,m-1})/dt, th) + (div z^{n+1,m}, th)
///     = (Q(t_m), th) + (L (p^{n,m} - p^{n,m-1})/dt, th)
///       - ((alpha/q) div(u^n - u_K)/dt, th)
/// (with BDF2, dt / c0 and the history values of set_time_history in place
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
  const TimeDerivative& d = w.derivative;
  for (int m = 1; m <= w.q; ++m)
  {
    set_time_history(_flow, w, m, w.p_new, w.u_old);
    assign(*_flow.p_iterate, w.p_old[m]);
    assign(*_flow.p_iterate_previous, history_value(d, w.p_old[m - 1], m >= 2 ? w.p_old[m - 2] : _p_before));
    _flow.set_fine_step(m, w.fault_new[m - 1], fault_reference(w, m));
    _flow.solve(t(w, m));
    w.p_new[m] = values(_flow.pressure->x()->array());
    std::span<const double> z_p = _flow.unknowns();
    w.w_new[m].assign(z_p.begin(), z_p.end());
    w.fault_new[m] = _flow.fault_pressure();
  }
}

/// The reference of the conduit faults' fixed-stress term at fine step m,
/// p_f^{n,m} - p_f^{n,m-1} + p_f^{n+1,m-1}: the fault's (S + L)(p_f^{n+1,m} -
/// p_f^{n+1,m-1}) = L (p_f^{n,m} - p_f^{n,m-1}) + ... as the rock's eq. 4.17.
Array FixedStressSplit::fault_reference(const Window& w, int m) const
{
  if (m == 1) // p_f^{n,0} = p_f^{n+1,0}: the window's start
    return w.fault_old[1];
  Array reference = difference(w.fault_old[m], w.fault_old[m - 1]);
  for (std::size_t i = 0; i < reference.size(); ++i)
    reference[i] += w.fault_new[m - 1][i];
  return reference;
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
    second_pass_correction(w);
}

/// The second pass of "multirate-two-pass" (docs/multirate-two-pass.md). The printed
/// multirate scheme damps the fine-step pressure modes that sum to zero
/// over the window only by L/(S+L) ~ gamma per iteration: the mechanics
/// sees p^q alone. Here the fine steps are recomputed without L, from p_K
/// and with the new displacement u^{n+1}:
///   (S (p^B_m - p^B_{m-1})/dt, th) + (div z^B_m, th)
///     = (Q(t_m), th) - ((alpha/q) div(u^{n+1} - u_K)/dt, th),
/// so they hold no error of their own, only that of u^{n+1}; the window end
/// keeps the first pass's value p^A_q (the one the mechanics used) through
///   p^{n+1,m} = p^B_m + (m/q)(p^A_q - p^B_q),   m = 1..q,
/// the same linear correction applied to the mixed states (z, p). At the
/// fixed point p^B = p^A: the fixed point is that of the printed scheme.
void FixedStressSplit::second_pass_correction(Window& w)
{
  FlowStep& second = *_second_pass;
  const int q = w.q;
  std::vector<Array> p_B(q + 1, _p_K), w_B(q + 1), fault_B(q + 1, w.fault_new[0]);
  assign(*second.u_iterate, w.u_new);
  if (conduits())
    second.take_start_apertures(_flow);
  for (int m = 1; m <= q; ++m)
  {
    set_time_history(second, w, m, p_B, w.u_new);
    second.set_fine_step(m, fault_B[m - 1], fault_B[m - 1]); // no L: the iterate is only the guess
    second.solve(t(w, m));
    p_B[m] = values(second.pressure->x()->array());
    w_B[m] = values(second.unknowns());
    fault_B[m] = second.fault_pressure();
  }
  const Array p_end = difference(w.p_new[q], p_B[q]), w_end = difference(w.w_new[q], w_B[q]);
  for (int m = 1; m < q; ++m)
  {
    const double s = static_cast<double>(m) / q;
    for (std::size_t i = 0; i < p_end.size(); ++i)
      w.p_new[m][i] = p_B[m][i] + s * p_end[i];
    for (std::size_t i = 0; i < w_end.size(); ++i)
      w.w_new[m][i] = w_B[m][i] + s * w_end[i];
    // The conduit faults' pressures are the tail of the mixed states.
    const std::size_t n = w.w_new[m].size() - w.fault_new[m].size();
    std::copy(w.w_new[m].begin() + n, w.w_new[m].end(), w.fault_new[m].begin());
  }
}

/// The contraction quantities of this iteration's increments, with the
/// coefficients of each cell's material: Theorem 1,
///   delta sigma_v^{n+1} = lambda div(du) - alpha dp,
/// for the single-rate split, Theorem 2,
///   delta sigma^{n+1,m} = (dp^m - dp^{m-1}) - alpha/(qL) div du,
/// (summed over m in l2) for the multirate ones.
Increments FixedStressSplit::measure_contraction(const Window& w, int n) const
{
  using Quantity = ContractionNorm::Quantity;
  Increments inc;
  inc.du = difference(w.u_new, w.u_old);
  Array dp_previous(_p_K.size(), 0.0);
  for (int m = 1; m <= w.q; ++m)
  {
    const Array dp = difference(w.p_new[m], w.p_old[m]);
    if (_stabilised)
    {
      const Array change = difference(dp, dp_previous);
      const double t2 = m == 1 ? _contraction(Quantity::theorem2, inc.du, change)
                               : _contraction(Quantity::theorem2, change); // the same du
      const double r = _contraction(Quantity::coupled_residual, change);
      inc.theorem2 += t2 * t2;
      inc.residual += r * r;
    }
    dp_previous = dp;
    const double dpn = owned_norm(dp, _Q), pn = owned_norm(w.p_new[m], _Q);
    inc.dp2 += dpn * dpn;
    inc.p2 += pn * pn;
  }
  // ||dp_f||^2 and ||p_f||^2 summed over the fine steps; as p's, their
  // root mean square over the window.
  std::array<double, 2> fault{0.0, 0.0};
  for (int m = 1; m <= w.q; ++m)
    for (std::size_t i = 0; i < w.fault_new[m].size(); ++i)
      fault[0] += std::pow(w.fault_new[m][i] - w.fault_old[m][i], 2), fault[1] += std::pow(w.fault_new[m][i], 2);
  MPI_Allreduce(MPI_IN_PLACE, fault.data(), 2, MPI_DOUBLE, MPI_SUM, _V.mesh()->comm());
  inc.fault_dp = std::sqrt(fault[0] / w.q), inc.fault_p = std::sqrt(fault[1] / w.q);
  inc.theorem2 = _stabilised ? std::sqrt(inc.theorem2) : std::numeric_limits<double>::quiet_NaN();
  inc.residual = std::sqrt(inc.residual);
  if (_coupling.multirate())
    inc.dsigma = inc.theorem2;
  else
    inc.dsigma = _contraction(Quantity::theorem1, inc.du, difference(w.p_new[1], w.p_old[1]));
  inc.ratio = n > 0 ? inc.dsigma / w.dsigma_previous : std::numeric_limits<double>::quiet_NaN();
  return inc;
}

/// A ratio is held against gamma from the second one on, while the
/// increments are resolved:
/// - the first ratio compares with delta sigma^1 = sigma^1 - sigma^0, and
///   u^0 = u_K is no mechanics solution at this step's loads, which the
///   proof of Theorem 1 needs for both iterates it subtracts;
/// - once ||delta sigma|| has fallen six orders below the window's first
///   one, or below 1e-9 of the norm of the quantity itself, it is made of the
///   round-off of the solves (the displacement carries ~1e-11 relative
///   round-off, amplified by div).
/// The other ratios are logged and counted as unresolved. With acceleration
/// the iterates are no longer x^{n+1} = G(x^n): ratios are logged only.
void FixedStressSplit::hold_against_gamma(Window& w, const Increments& inc, int n)
{
  const double ratio = inc.ratio;
  if (n == 0)
    w.dsigma_first = inc.dsigma;
  using Quantity = ContractionNorm::Quantity;
  const double size = _coupling.multirate() ? _contraction(Quantity::theorem2, w.u_new, w.p_new[w.q])
                                            : _contraction(Quantity::theorem1, w.u_new, w.p_new[1]);
  const bool resolved = !_accelerated and n > 1 and inc.dsigma >= resolved_fraction * w.dsigma_first
                        and inc.dsigma >= round_off_fraction * size;
  if (n > 0 and !resolved)
    ++_report.unresolved_ratios;
  if (resolved and std::isfinite(ratio))
  {
    _report.max_contraction_ratio = std::max(_report.max_contraction_ratio, ratio);
    _state.ratio_sum += ratio;
    ++_report.ratios;
    if (ratio > _parameters.gamma)
      ++_report.bound_violations;
  }
  w.dsigma_previous = inc.dsigma;
}

/// The stopping test's increments (dp, du), logged: l2 norms of the p (root
/// mean square over the window's fine steps) and u increments relative to
/// the largest p and u of the run so far (relative
/// to the current iterate alone, a field decaying to zero, e.g. p at steady
/// state, would be judged by its round-off). Never on a stale state. With
/// conduit faults dp is the larger of the rock's and the faults' p_f
/// increment (relative to the largest p_f so far), both logged, with the
/// faults' contraction ratio ||dp_f^{n+1}|| / ||dp_f^n||.
std::pair<double, double> FixedStressSplit::stopping_test(Window& w, const Increments& inc, int n)
{
  _state.p_size = std::max(_state.p_size, std::sqrt(inc.p2 / w.q));
  _state.u_size = std::max(_state.u_size, owned_norm(w.u_new, _V));
  _state.fault_p_size = std::max(_state.fault_p_size, inc.fault_p);
  const double dp_norm = relative(std::sqrt(inc.dp2 / w.q), _state.p_size);
  const double du_norm = relative(owned_norm(inc.du, _V), _state.u_size);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const bool conduits = this->conduits();
  const double fault_dp = conduits ? relative(inc.fault_dp, _state.fault_p_size) : nan;
  const double fault_ratio = conduits and n > 0 and w.fault_previous > 0 ? inc.fault_dp / w.fault_previous : nan;
  w.fault_previous = inc.fault_dp;
  w.active = _mechanics.active_contact_set();
  _observer.record({w.K + 1, t(w, w.q), n + 1, inc.dsigma, inc.ratio, _parameters.gamma, dp_norm, du_norm,
                    w.active.nodes, fault_dp, fault_ratio, w.newton_steps});
  if (!std::isfinite(inc.p2) or !std::isfinite(_state.u_size))
    // The iterates hold NaN or inf (a load or coefficient that is not
    // finite): no further iteration can recover.
    throw SolverError("non-finite values (NaN or inf) in the "
                      + std::string(std::isfinite(inc.p2) ? "displacement" : "pressure"));
  std::ostringstream entry;
  entry << " " << n + 1 << ": dp " << dp_norm << " du " << du_norm << " dsigma " << inc.dsigma;
  if (conduits)
    entry << " dp_f " << fault_dp;
  entry << ";";
  w.log.push_back(entry.str());
  return {conduits ? std::max(dp_norm, fault_dp) : dp_norm, du_norm};
}

/// The iterate the next flow pass reads: the map value (p^{n+1}, u^{n+1}),
/// or with Anderson a combination of the last map values. The differences
/// of earlier iterations describe the map of their contact active set
/// only: a new set restarts the history.
void FixedStressSplit::next_iterate(Window& w)
{
  if (!w.anderson)
  {
    w.p_old = w.p_new;
    w.u_old = w.u_new;
    return;
  }
  if (const long changes = contact_changes(_mechanics); changes != w.active_set_changes)
  {
    w.anderson->restart();
    w.active_set_changes = changes;
  }
  State x(w.p_old.begin() + 1, w.p_old.end()), g(w.p_new.begin() + 1, w.p_new.end());
  x.push_back(w.u_old);
  g.push_back(w.u_new);
  w.anderson->next(x, g);
  std::copy(x.begin(), x.begin() + w.q, w.p_old.begin() + 1);
  w.u_old = x.back();
}

/// Coupled residual of an accepted state: the flow equations with u^{n+1}
/// in place of u^n differ by L(dp^m - dp^{m-1}) - (alpha/q) div du
/// = L delta sigma^{n+1,m}; relative to the fluid content change.
void FixedStressSplit::record_coupled_residual(const Window& w, const Increments& inc)
{
  if (!_stabilised)
    return;
  const double change = _contraction(ContractionNorm::Quantity::fluid_content, difference(w.u_new, _u_K),
                                     difference(w.p_new[w.q], _p_K));
  _report.max_coupled_residual = std::max(_report.max_coupled_residual, change > 0 ? inc.residual / change : 0.0);
}

/// One coupling iteration n of window w; true when it converged.
bool FixedStressSplit::iteration(Window& w, int n)
{
  flow_pass(w);
  mechanics_pass(w);
  const Increments inc = measure_contraction(w, n);
  hold_against_gamma(w, inc, n);
  const auto [dp_norm, du_norm] = stopping_test(w, inc, n);
  next_iterate(w);
  if (_observer.iteration)
    _observer.iteration(w.K + 1, n + 1, dp_norm, du_norm);
  w.increment = std::max(dp_norm, du_norm);
  const double tolerance = stopping_tolerance(w);
  const bool converged = dp_norm <= tolerance and du_norm <= tolerance;
  if (converged)
  {
    record_coupled_residual(w, inc);
    // Compared once per window, on the converged iterate (one collective).
    w.contact_changed = !same_active_set(w.active, _active_K, _V.mesh()->comm());
  }
  return converged;
}

/// The coupling tolerance of window w: coupling.tolerance, and under
/// time.adaptive at most a tenth of the error tolerance per unit step,
/// tolerance h / t. The iteration's own error enters the error estimate
/// multiplied by t / h (step_control.h); above that bound it would keep
/// short steps short (a crawl at dt_min, docs/theory.md "Adaptive steps").
double FixedStressSplit::stopping_tolerance(const Window& w) const
{
  if (!_control)
    return _coupling.tolerance;
  const double per_unit_step = _scene.adaptive->tolerance * _grid.dt[w.j] / t(w, w.q);
  return std::min(_coupling.tolerance, 0.1 * per_unit_step);
}

/// Iterates window w to convergence (n ends as the last iteration's index).
FixedStressSplit::Outcome FixedStressSplit::iterate_window(Window& w, int& n)
{
  try
  {
    for (n = 0; n < _coupling.max_iterations; ++n)
      if (iteration(w, n))
        return Outcome::converged;
  }
  catch (const SolverError& e)
  {
    // The failing solve named its system; the iteration is known here.
    const std::string cause = "coupling iteration " + std::to_string(n + 1) + ": " + e.what();
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
  assign(*_mechanics.u, _u_K);
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
    std::ostringstream message;
    message << "step " << w.K + 1 << " (t = " << t(w, m) << "): " << failure;
    if (retry(w, message.str()))
      return false;
    _report.mean_contraction_ratio = _report.ratios ? _state.ratio_sum / _report.ratios : 0.0;
    throw CouplingError(message.str());
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

/// The error of a window that did not converge in coupling.max_iterations,
/// with the last increments.
CouplingError FixedStressSplit::not_converged(const Window& w)
{
  std::ostringstream message;
  message << "the fixed-stress split did not converge in " << _coupling.max_iterations
          << " iterations at t = " << t(w, w.q) << " (step " << w.K + 1 << "); last increments:";
  for (std::size_t i = w.log.size() > 3 ? w.log.size() - 3 : 0; i < w.log.size(); ++i)
    message << w.log[i];
  message << " " << _advice;
  return CouplingError(message.str());
}

/// Accept the window: write every fine flow step, then the mechanics step;
/// its end state is the next window's start.
void FixedStressSplit::accept_window(const Window& w, int n)
{
  _attempts = 0;
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
  _p_before = w.p_new[w.q - 1]; // p_K itself for q = 1
  _u_path_before = path(w, w.u_new, w.q - 1);
  _u_before = _u_K;
  _j_before = w.j;
  assign(*_flow.p_before, _p_before);
  assign(*_flow.u_before, _u_before);
  assign(*_flow.u_path_before, _u_path_before);
  _p_K = w.p_new[w.q];
  _u_K = w.u_new;
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
    if (outcome == Outcome::not_converged and !retry(w, "the fixed-stress split did not converge"))
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
