// The paper's contraction theorems measured on every coupling iteration of
// the fixed-stress split: the increments of a window's iterates, their
// ||delta sigma|| (Theorem 1 single-rate, Theorem 2 multirate) and its ratio
// held against gamma while resolved, the stopping test's relative
// increments and the coupled residual of an accepted state (docs/theory.md,
// "The theorems' quantities"). Twin: python_prototype/coupling/contraction.py.
#pragma once

#include "assembly/problem.h"
#include "coupling/coupling.h"
#include "coupling/window.h"
#include "diagnostics/diagnostics.h"

#include <memory>
#include <span>
#include <vector>

namespace biotcontact
{

/// increment / size, or the increment itself while size = 0.
inline double relative(double increment, double size) { return size > 0 ? increment / size : increment; }

/// @brief What one coupling iteration measured on its increments.
struct Increments
{
  std::vector<double> du;
  double dsigma = 0;   // ||delta sigma|| of Theorem 1 (q = 1) or 2 (multirate)
  double theorem2 = 0; // Theorem 2's quantity (NaN without L)
  double residual = 0; // L times it, cell by cell (ContractionNorm::Quantity::coupled_residual)
  double ratio = 0;    // dsigma / the previous iteration's (NaN at n = 0)
  double dp2 = 0, p2 = 0;
  double fault_dp = 0, fault_p = 0; // ||dp_f|| and ||p_f|| (l2 over the conduit cells; 0 without)
};

/// @brief The stopping test's increments of one iteration: dp and du
/// relative to the largest p and u of the run so far, and with conduit
/// faults dp_f relative to the largest p_f and the faults' ratio
/// ||dp_f^{n+1}|| / ||dp_f^n|| (NaN without).
struct StoppingIncrements
{
  double dp = 0, du = 0, fault_dp = 0, fault_ratio = 0;
};

/// @brief The contraction measures of the fixed-stress split's iterations,
/// counted into the run's report (CouplingRun).
class ContractionMeasure
{
public:
  ContractionMeasure(const Problem& problem, CouplingRun& run, std::shared_ptr<const dolfinx::fem::FunctionSpace> V,
                     std::shared_ptr<const dolfinx::fem::FunctionSpace> Q);
  /// Windows of q fine steps from now on (coupling.q = "auto").
  void set_window_steps(int q) { _norm.set_window_steps(q); }
  Increments measure(const Window& w, int n);
  void hold_against_gamma(Window& w, const Increments& inc, int n);
  StoppingIncrements stopping_increments(Window& w, const Increments& inc, int n, bool conduits);
  void record_coupled_residual(const Window& w, const Increments& inc, const WindowHistory& history,
                               double tolerance);

private:
  /// ||alpha div u|| + ||S p||: the fluid content's two terms, each by its norm.
  double fluid_content_terms(std::span<const double> u, std::span<const double> p);
  ContractionNorm _norm;
  const bool _stabilised; // L > 0 in some cell: Theorem 2's quantity is measured
  const bool _multirate;
  const double _gamma;
  const dolfinx::fem::FunctionSpace& _V;
  const dolfinx::fem::FunctionSpace& _Q;
  CouplingReport& _report;
  ControllerState& _state;
};

} // namespace biotcontact
