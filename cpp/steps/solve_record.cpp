#include "steps/solve_record.h"

#include <cmath>

namespace biotcontact
{

namespace
{
std::array<FieldValues, 3> each(const SolveFields& f) { return {f.p, f.u, f.fault_p}; }
} // namespace

void SolveMeter::start(const SolveFields& fields, long newton_steps)
{
  const std::array<FieldValues, 3> all = each(fields);
  for (std::size_t i = 0; i < all.size(); ++i)
    _before[i].assign(all[i].values.begin(), all[i].values.begin() + all[i].owned);
  _newton_steps = newton_steps;
}

SolveRecord SolveMeter::record(const SolveFields& fields, long newton_steps, int active_nodes) const
{
  // Per field the squares of the change and of the field, this rank's.
  const std::array<FieldValues, 3> all = each(fields);
  std::array<double, 6> squares{};
  for (std::size_t i = 0; i < all.size(); ++i)
    for (std::int32_t k = 0; k < all[i].owned; ++k)
    {
      const double v = all[i].values[k];
      squares[2 * i] += (v - _before[i][k]) * (v - _before[i][k]);
      squares[2 * i + 1] += v * v;
    }
  MPI_Allreduce(MPI_IN_PLACE, squares.data(), 6, MPI_DOUBLE, MPI_SUM, fields.comm);
  std::array<double, 6> norms;
  for (std::size_t j = 0; j < norms.size(); ++j)
    norms[j] = all[j / 2].present ? std::sqrt(squares[j]) : SolveRecord::none;
  return {norms[0], norms[1], norms[2], norms[3], norms[4], norms[5], active_nodes, newton_steps - _newton_steps};
}

SolveRecord SolveMeter::failed(long newton_steps, int active_nodes) const
{
  SolveRecord r;
  r.active_nodes = active_nodes;
  r.newton_steps = newton_steps - _newton_steps;
  return r;
}

} // namespace biotcontact
