#include "coupling/two_pass.h"

#include "assembly/linear_algebra.h"

#include <algorithm>

namespace biotcontact
{

void second_pass_correction(FlowStep& second, FlowStep& flow, Window& w, const WindowHistory& history)
{
  const int q = w.q;
  std::vector<std::vector<double>> p_B(q + 1, history.p_K), w_B(q + 1), fault_B(q + 1, w.fault_new[0]);
  assign(*second.u_iterate, w.u_new);
  if (flow.fault_aperture()) // conduit faults
    second.take_start_apertures(flow);
  for (int m = 1; m <= q; ++m)
  {
    history.set_time_history(second, w, m, p_B, w.u_new);
    second.set_fine_step(m, fault_B[m - 1], fault_B[m - 1]); // no L: the iterate is only the guess
    second.solve(history.t(w, m));
    p_B[m] = values(second.pressure->x()->array());
    w_B[m] = values(second.unknowns());
    fault_B[m] = second.fault_pressure();
  }
  const std::vector<double> p_end = difference(w.p_new[q], p_B[q]), w_end = difference(w.w_new[q], w_B[q]);
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

} // namespace biotcontact
