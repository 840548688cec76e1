// A window of the fixed-stress split, [t_K, t_{K+1}]: q fine flow steps and
// one mechanics step (paper section 4). Its iterates, and what the time
// scheme keeps of the windows before it: the flow's time history and the
// displacement's path across the window (backward Euler or BDF2,
// docs/theory.md "Time schemes"). Twin: python_prototype/coupling/window.py.
#pragma once

#include "contact/contact_state.h"
#include "coupling/anderson.h"
#include "steps/flow_step.h"
#include "time/time_grid.h"
#include "time/time_scheme.h"

#include <limits>
#include <optional>
#include <string>
#include <vector>

namespace biotcontact
{

/// @brief One window's iterates: p^{n,m} and p^{n+1,m} (m = 0..q; m = 0 is
/// p_K), u^n and u^{n+1}, the mixed states (z, p)^{n+1,m}, and what the
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
  std::vector<std::vector<double>> p_old, p_new, w_new;
  std::vector<double> u_old, u_new;
  // The conduit faults' p_f^{n,m} and p_f^{n+1,m} (m = 0..q, this rank's entries).
  std::vector<std::vector<double>> fault_old, fault_new;
  std::optional<AndersonAcceleration> anderson;
  bool accelerated = false;            // Anderson's took part in the window (its ratios are not G's)
  long active_set_changes = 0;         // at the last Anderson restart
  double dsigma_previous = std::numeric_limits<double>::quiet_NaN(), dsigma_first = 0;
  double fault_previous = std::numeric_limits<double>::quiet_NaN(); // ||dp_f|| of the last iteration
  long newton_steps = 0; // of the last mechanics pass's contact solve
  double increment = 1;                // max(dp, du) of the last iteration
  std::vector<std::string> log;        // the last iterations, for the error message
  std::vector<std::int64_t> active_nodes; // per iteration: the contact set's active nodes (coupling/cycle.h)
  std::vector<double> increments;      // per iteration: max(dp, du)
  int cycle = 0;                       // the period of the cycle that ended the iteration, 0 for none
  std::vector<std::vector<std::int8_t>> flags; // the active sets of the last iterations (coupling/pins.h), this rank's
  std::vector<std::int8_t> pins;       // the contact constraints' pins (coupling/pins.h), this rank's
  int pin_rounds = 0;                  // rounds of pins so far; -1: released after max_pin_rounds
  std::size_t pinned_at = 0;           // the iterations before the last pins (their records cleared)
};

/// @brief What the one-line error of a window that failed says besides the
/// window's own record: the time it ended at, the iteration limit, the
/// scheme's advice (gamma and what converges instead) and whether to
/// propose time.retry (a scene with contact that does not retry).
struct WindowFailure
{
  double t;
  int max_iterations;
  std::string advice;
  bool propose_retry = false;
};

/// The one-line error of window w that did not converge in max_iterations
/// or cycled (coupling/cycle.h), with its last three increments.
std::string not_converged_message(const Window& w, const WindowFailure& failure);

/// The scales Anderson's norm weighs a window's blocks by: the owned
/// entries of a pressure and of u, and the largest p (a fine step's) and u
/// so far, the scales of the stopping test.
struct AndersonScales
{
  std::int32_t p_owned, u_owned;
  double p_size, u_size;
};

/// Anderson's method from here on in window w (coupling/anderson.h), on its
/// state (p^1, ..., p^q, u), the window's q pressures weighing as one field.
void accelerate_window(Window& w, MPI_Comm comm, int depth, const AndersonScales& scales);

/// The iterate the next flow pass reads with Anderson's method: the
/// combination of w's last map values (p^{n+1}, u^{n+1}).
void mix_iterates(Window& w);

/// The reference of the conduit faults' fixed-stress term at fine step m,
/// p_f^{n,m} - p_f^{n,m-1} + p_f^{n+1,m-1}: the fault's (S + L)(p_f^{n+1,m} -
/// p_f^{n+1,m-1}) = L (p_f^{n,m} - p_f^{n,m-1}) + ... as the rock's eq. 4.17.
std::vector<double> fault_reference(const Window& w, int m);

/// "step K (t = t)": window w in a message.
std::string window_name(const Window& w, double t);

/// The log's line where coupling.acceleration = "auto" hands window w
/// (at t) to Anderson's method, `left` iterations left.
std::string stagnation_note(const Window& w, double t, int left);

/// @brief The converged state at t_K and, for BDF2, what the windows before
/// left: the pressure one fine step and the displacement one window before
/// t_K, the displacement path's value one fine step before t_K and the
/// previous window's first fine step. From them, a window's time
/// derivative, its displacement path and its fine steps' time history.
struct WindowHistory
{
  WindowHistory(TimeScheme scheme, const TimeGrid& grid) : scheme(scheme), grid(grid) {}

  /// The state at the start (t = 0 or a restart's window): p_K and the
  /// BDF2 values from `flow` (a restart restored them), u_K = u, and the
  /// first fine step of the window before.
  void start(const FlowStep& flow, std::span<const double> u, int j_previous);
  /// Fine time m of window w (t_K + m dt for a constant step).
  double t(const Window& w, int m) const { return grid.t[w.j + m]; }
  TimeDerivative derivative(int j, int q) const;
  std::vector<double> path(const Window& w, const std::vector<double>& u, int m) const;
  void set_time_history(FlowStep& flow, const Window& w, int m, const std::vector<std::vector<double>>& p,
                        const std::vector<double>& u) const;
  /// The history value of the iterates p[0..m-1] before fine step m.
  std::vector<double> previous(const Window& w, const std::vector<std::vector<double>>& p, int m) const;
  /// The accepted window w's end is the next window's start; `flow` keeps
  /// the BDF2 values for a checkpoint.
  void accept(const Window& w, FlowStep& flow);

  TimeScheme scheme;
  const TimeGrid& grid; // a retry refines it
  std::vector<double> p_K, u_K;
  std::vector<double> p_before, u_before, u_path_before;
  int j_before = 0;
};

} // namespace biotcontact
