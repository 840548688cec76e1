// What one solve of a step measured, a row of iterations.csv for the
// schemes with one solve per step (coupling/single_solve.h): the monolithic
// system (one row per iteration on its conduit faults' apertures) and a
// single physics. The prototype's twin is python_prototype/steps/solve_record.py.
#pragma once

#include <array>
#include <cstdint>
#include <limits>
#include <mpi.h>
#include <span>
#include <vector>

namespace biotcontact
{

/// @brief What one solve measured: the l2 norms of p, u and the conduit
/// faults' p_f after it and of their change since the solve before (the
/// step's start for the first; NaN where the step has no such field), and
/// its contact solve's Newton steps and active nodes. The scheme makes the
/// changes relative, as the split's stopping test does.
struct SolveRecord
{
  static constexpr double none = std::numeric_limits<double>::quiet_NaN();
  double dp = none, p = none, du = none, u = none, fault_dp = none, fault_p = none;
  int active_nodes = 0;
  long newton_steps = 0;
};

/// A field a solve moves: its values on this rank and how many of the first
/// are held by this rank alone (the rest are ghosts or copies), so that
/// each value counts once over the ranks.
struct FieldValues
{
  std::span<const double> values;
  std::int32_t owned = 0;
  bool present = false; // false: the step has no such field
};

/// @brief The fields of a step that its solves move: p, u and p_f, and
/// the communicator of their ranks.
struct SolveFields
{
  FieldValues p, u, fault_p;
  MPI_Comm comm;
};

/// @brief Measures a step's solves: remembers the fields before a solve
/// and records its change.
class SolveMeter
{
public:
  /// The fields (and the contact Newton steps so far) before a solve.
  void start(const SolveFields& fields, long newton_steps);
  /// The record of the solve since start() (collective): the fields and
  /// Newton steps now, the active nodes after it.
  SolveRecord record(const SolveFields& fields, long newton_steps, int active_nodes) const;
  /// The record of a solve since start() that failed: its Newton steps, no
  /// change of the fields (NaN: it left them as they were).
  SolveRecord failed(long newton_steps, int active_nodes) const;

private:
  std::array<std::vector<double>, 3> _before;
  long _newton_steps = 0;
};

} // namespace biotcontact
