#include "coupling/contraction.h"

#include "assembly/linear_algebra.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

namespace biotcontact
{

namespace
{
/// Ratios measured below this fraction of a window's first ||delta sigma||
/// are at round-off level (see hold_against_gamma).
constexpr double resolved_fraction = 1e-6;
constexpr double round_off_fraction = 1e-9;
} // namespace

ContractionMeasure::ContractionMeasure(const Problem& problem, CouplingRun& run,
                                       std::shared_ptr<const dolfinx::fem::FunctionSpace> V,
                                       std::shared_ptr<const dolfinx::fem::FunctionSpace> Q)
    : _norm(problem.forms, problem.materials, problem.parameters.q, V, Q),
      _stabilised(problem.materials.max_L > 0), _multirate(problem.scene.coupling->multirate()),
      _gamma(problem.parameters.gamma), _V(*V), _Q(*Q), _report(run.report), _state(run.state)
{
}

/// The contraction quantities of this iteration's increments, with the
/// coefficients of each cell's material: Theorem 1,
///   delta sigma_v^{n+1} = lambda div(du) - alpha dp,
/// for the single-rate split, Theorem 2,
///   delta sigma^{n+1,m} = (dp^m - dp^{m-1}) - alpha/(qL) div du,
/// (summed over m in l2) for the multirate ones.
Increments ContractionMeasure::measure(const Window& w, int n)
{
  using Quantity = ContractionNorm::Quantity;
  Increments inc;
  inc.du = difference(w.u_new, w.u_old);
  std::vector<double> dp_previous(w.p_new[0].size(), 0.0);
  for (int m = 1; m <= w.q; ++m)
  {
    const std::vector<double> dp = difference(w.p_new[m], w.p_old[m]);
    if (_stabilised)
    {
      const std::vector<double> change = difference(dp, dp_previous);
      const double t2 = m == 1 ? _norm(Quantity::theorem2, inc.du, change)
                               : _norm(Quantity::theorem2, change); // the same du
      const double r = _norm(Quantity::coupled_residual, change);
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
  if (_multirate)
    inc.dsigma = inc.theorem2;
  else
    inc.dsigma = _norm(Quantity::theorem1, inc.du, difference(w.p_new[1], w.p_old[1]));
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
void ContractionMeasure::hold_against_gamma(Window& w, const Increments& inc, int n)
{
  const double ratio = inc.ratio;
  if (n == 0)
    w.dsigma_first = inc.dsigma;
  using Quantity = ContractionNorm::Quantity;
  const double size = _multirate ? _norm(Quantity::theorem2, w.u_new, w.p_new[w.q])
                                 : _norm(Quantity::theorem1, w.u_new, w.p_new[1]);
  const bool resolved = !w.accelerated and n > 1 and inc.dsigma >= resolved_fraction * w.dsigma_first
                        and inc.dsigma >= round_off_fraction * size;
  if (n > 0 and !resolved)
    ++_report.unresolved_ratios;
  if (resolved and std::isfinite(ratio))
  {
    _report.max_contraction_ratio = std::max(_report.max_contraction_ratio, ratio);
    _state.ratio_sum += ratio;
    ++_report.ratios;
    if (ratio > _gamma)
      ++_report.bound_violations;
  }
  w.dsigma_previous = inc.dsigma;
}

/// The stopping test's increments: l2 norms of the p (root mean square over
/// the window's fine steps) and u increments relative to the largest p and
/// u of the run so far (relative to the current iterate alone, a field
/// decaying to zero, e.g. p at steady state, would be judged by its
/// round-off). With conduit faults also the p_f increment relative to the
/// largest p_f so far, and the faults' contraction ratio.
StoppingIncrements ContractionMeasure::stopping_increments(Window& w, const Increments& inc, int n, bool conduits)
{
  _state.p_size = std::max(_state.p_size, std::sqrt(inc.p2 / w.q));
  _state.u_size = std::max(_state.u_size, owned_norm(w.u_new, _V));
  _state.fault_p_size = std::max(_state.fault_p_size, inc.fault_p);
  StoppingIncrements s;
  s.dp = relative(std::sqrt(inc.dp2 / w.q), _state.p_size);
  s.du = relative(owned_norm(inc.du, _V), _state.u_size);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  s.fault_dp = conduits ? relative(inc.fault_dp, _state.fault_p_size) : nan;
  s.fault_ratio = conduits and n > 0 and w.fault_previous > 0 ? inc.fault_dp / w.fault_previous : nan;
  w.fault_previous = inc.fault_dp;
  return s;
}

/// Coupled residual of an accepted state: the flow equations with u^{n+1}
/// in place of u^n differ by L(dp^m - dp^{m-1}) - (alpha/q) div du
/// = L delta sigma^{n+1,m}; relative to the step's change of the fluid
/// content's two terms, ||alpha div du|| + ||S dp||, not of their sum: an
/// undrained step (an impermeable rock) changes them alike and its fluid
/// content not at all, and the ratio was then 1 where the split had
/// converged. A step that changes them by no more than `tolerance` of the
/// state's own resolves no residual and is not recorded.
void ContractionMeasure::record_coupled_residual(const Window& w, const Increments& inc, const WindowHistory& history,
                                                 double tolerance)
{
  if (!_stabilised)
    return;
  const double change = fluid_content_terms(difference(w.u_new, history.u_K), difference(w.p_new[w.q], history.p_K));
  if (change > tolerance * fluid_content_terms(w.u_new, w.p_new[w.q]))
    _report.max_coupled_residual = std::max(_report.max_coupled_residual, inc.residual / change);
}

double ContractionMeasure::fluid_content_terms(std::span<const double> u, std::span<const double> p)
{
  using Quantity = ContractionNorm::Quantity;
  const std::vector<double> no_u(u.size(), 0.0), no_p(p.size(), 0.0);
  return _norm(Quantity::fluid_content, u, no_p) + _norm(Quantity::fluid_content, no_u, p);
}

} // namespace biotcontact
