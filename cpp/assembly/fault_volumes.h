// The fluid volumes of the conduit faults: each fault's volumes since the
// run's start and of each step, their balance (injected + exchanged +
// intersections = stored + outflow, docs/theory.md "Converged means
// balanced") and the volume rates through the faults' intersections.
// ConduitFaults counts them (fault_flow_volumes.cpp). Twin:
// python_prototype/assembly/fault_volumes.py.
#pragma once

#include <string>
#include <vector>

namespace biotcontact
{

/// @brief A conduit fault's fluid volumes since the run's start (m^3; m^2
/// per metre of thickness in 2D): injected by its wells, stored (the
/// volume its opening made and its fluid's compression), exchanged (from
/// the rock through its faces), out of its ends on pressure boundaries and
/// in from the other conduit faults where they meet (intersections). Step by
/// step, injected + exchanged + intersections = stored + outflow.
struct FaultVolumes
{
  double injected = 0, stored = 0, exchanged = 0, outflow = 0, intersections = 0;
};

/// @brief A fault's volumes of one step (net); the sum of the magnitudes
/// of every face's, well's, cell's and end's term in them (gross); the
/// fluid it holds at the step's end (held, sum of w_h |k|); and dt sum
/// |c_i| over its faces (faces: times the rock's largest flux DOF, the
/// exchange the rock's round-off can make).
struct StepVolumes
{
  FaultVolumes net;
  double gross = 0, held = 0, faces = 0;
};

/// @brief Where a set of conduit faults meets (their junctions of
/// fault_network: a point in 2D, a line's edges in 3D): the faults, in the
/// scene's order, the number of junctions and the volume rate through them
/// at the last accepted step's end (m^3/s; m^2/s per metre of thickness in
/// 2D), at each junction the sum of its members' flows into it (which the
/// flows out of it equal).
struct IntersectionRate
{
  std::vector<std::string> faults;
  std::size_t junctions = 0;
  double rate = 0;
};

/// How far an accepted step may leave a fault's volumes unbalanced
/// (volume_imbalance). Converged runs measure up to 6e-6 (the 3D closure
/// box with its flow solved by the Krylov method, whose tolerance is
/// relative to a load inflated by the held ends); the wrong answers this
/// stops, 1e-4 and more (docs/theory.md, "Converged means balanced").
constexpr double volume_balance_tolerance = 1e-5;

/// The imbalance |injected + exchanged - stored - outflow| of `step`
/// relative to the largest of `total` (the fault's volumes since the
/// start, the step included), the step's gross volume, 1e-6 of the fluid
/// the fault holds and 1e-8 of step.faces times `rock_flux`, the rock's
/// largest flux DOF (at the tolerance, 1e-11 and 1e-13 of them: round-off):
/// 0 when nothing moved.
double volume_imbalance(const StepVolumes& step, const FaultVolumes& total, double rock_flux);

} // namespace biotcontact
