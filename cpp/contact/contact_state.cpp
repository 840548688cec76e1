#include "contact/contact_state.h"

#include "assembly/petsc_error.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>

namespace biotcontact
{
namespace
{
/// The state of the fault pair of constraint k but its status, from x',
/// x' at the start of the step and R'.
PairState pair_state(const ContactMeasurement& m, std::size_t k)
{
  const ContactSet& set = m.set;
  const int d = set.dim;
  const NodeMatrix& frame = set.pair_frame[k];
  PairState p{set.pair_node[k], set.boundary[k], m.distance[k], m.pressure[k], {0, 0, 0},
              {0, 0, 0}, PairStatus::open, {0, 0, 0}};
  // The + node's tangential rows r = 1..d-1 of x' = T x hold the jump's
  // tangential components in the pair's frame, w_J = R [u], and those of
  // R' the contact force on them (change_of_variables.h); R^T takes both
  // back to the global frame. The force becomes a traction as the normal
  // one does (-sign R'/lumped, sign +1 for a pair): the traction the + face
  // exerts on the - face, along the slip increment when the pair slips
  // (contact_law.h).
  if (set.junction_nodes[k][0] >= 0) // frictionless; the jump in u (junction_jumps)
  {
    for (int r = 1; r < d; ++r)
      for (int i = 0; i < d; ++i)
        for (int j = 0; j < d; ++j)
        {
          p.slip[i] += frame[d * r + i] * frame[d * r + j] * m.jump[k][j];
          p.slip_increment[i] += frame[d * r + i] * frame[d * r + j] * (m.jump[k][j] - m.jump_start[k][j]);
        }
    return p;
  }
  for (int r = 1; r < d; ++r)
  {
    const std::int32_t row = m.displacement_dofs[set.dofs[k] + r];
    for (int i = 0; i < d; ++i)
    {
      p.slip[i] += frame[d * r + i] * m.x[row];
      p.slip_increment[i] += frame[d * r + i] * (m.x[row] - m.start[row]);
      p.tangential_traction[i] -= frame[d * r + i] * m.force[row] / set.lumped[k];
    }
  }
  return p;
}

} // namespace

std::vector<std::array<double, 3>> junction_jumps(const ContactSet& set, std::span<const std::int32_t> displacement_dofs,
                                                  Vec x, MPI_Comm comm)
{
  if (set.all_junction_nodes.empty()) // on every rank alike
    return {};
  // Each junction node's u from the rank that owns it, summed over the ranks.
  const int d = set.dim;
  const auto owned = static_cast<std::int64_t>(displacement_dofs.size());
  std::vector<double> values(d * set.all_junction_nodes.size(), 0.0);
  const PetscScalar* u;
  check_petsc(VecGetArrayRead(x, &u), "contact state: VecGetArrayRead of u");
  for (std::size_t v = 0; v < set.all_junction_nodes.size(); ++v)
    if (const std::int64_t first = d * set.all_junction_nodes[v] - set.dof_offset; first >= 0 and first < owned)
      for (int i = 0; i < d; ++i)
        values[d * v + i] = u[displacement_dofs[first + i]];
  check_petsc(VecRestoreArrayRead(x, &u), "contact state: VecRestoreArrayRead of u");
  MPI_Allreduce(MPI_IN_PLACE, values.data(), static_cast<int>(values.size()), MPI_DOUBLE, MPI_SUM, comm);
  std::map<std::int64_t, std::size_t> position;
  for (std::size_t v = 0; v < set.all_junction_nodes.size(); ++v)
    position.emplace(set.all_junction_nodes[v], v);
  std::vector<std::array<double, 3>> jumps(set.dofs.size(), {0, 0, 0});
  for (std::size_t k = 0; k < set.dofs.size(); ++k)
    if (const auto [plus, minus] = set.junction_nodes[k]; plus >= 0)
      for (int i = 0; i < d; ++i)
        jumps[k][i] = values[d * position.at(plus) + i] - values[d * position.at(minus) + i];
  return jumps;
}

namespace
{
/// The largest contact traction, normal or tangential, of the constraints
/// on all ranks: the scale of the states' tolerance (collective).
double traction_scale(std::span<const double> pressure, const std::vector<PairState>& pairs, MPI_Comm comm)
{
  double scale = 0;
  for (double p : pressure)
    scale = std::max(scale, std::abs(p));
  for (const PairState& p : pairs)
    scale = std::max(scale, std::hypot(p.tangential_traction[0], p.tangential_traction[1], p.tangential_traction[2]));
  MPI_Allreduce(MPI_IN_PLACE, &scale, 1, MPI_DOUBLE, MPI_MAX, comm);
  return scale;
}

/// Each fault's summary from its pairs' states (collective): the largest
/// opening and slip; the measures closed, slipping and stuck, and the
/// moment.
void summarise_faults(ContactState& s, const ContactMeasurement& m, const std::vector<std::size_t>& constraint,
                      const std::vector<int>& summary_of, MPI_Comm comm)
{
  const ContactSet& set = m.set;
  const double scale = traction_scale(m.pressure, s.pairs, comm);
  std::vector<double> largest(2 * s.faults.size(), 0.0), measure(4 * s.faults.size(), 0.0);
  for (std::size_t j = 0; j < s.pairs.size(); ++j)
  {
    PairState& p = s.pairs[j];
    const std::size_t k = constraint[j];
    const bool closed = on_foundation(m.distance[k], s.gap_scale);
    const auto& t = p.tangential_traction;
    // A junction's pairs are frictionless whatever their faults' laws
    // (theory.md, "Faults where they meet"): closed, they slip.
    const ContactLaw law = set.junction_nodes[k][0] >= 0 ? ContactLaw{} : constraint_law(set, k);
    p.status = pair_status(law, {closed, p.traction, std::hypot(t[0], t[1], t[2]), scale});
    p.cohesion = law.cohesion;
    const int f = summary_of[p.fault];
    largest[2 * f] = std::max(largest[2 * f], p.opening);
    largest[2 * f + 1] = std::max(largest[2 * f + 1], std::hypot(p.slip[0], p.slip[1], p.slip[2]));
    const auto& ds = p.slip_increment;
    measure[4 * f] += closed ? set.lumped[k] : 0.0;
    measure[4 * f + 1] += p.status == PairStatus::slip ? set.lumped[k] : 0.0;
    measure[4 * f + 2] += p.status == PairStatus::stick ? set.lumped[k] : 0.0;
    measure[4 * f + 3] += set.shear_modulus[k] * std::hypot(ds[0], ds[1], ds[2]) * set.lumped[k];
  }
  MPI_Allreduce(MPI_IN_PLACE, largest.data(), static_cast<int>(largest.size()), MPI_DOUBLE, MPI_MAX, comm);
  MPI_Allreduce(MPI_IN_PLACE, measure.data(), static_cast<int>(measure.size()), MPI_DOUBLE, MPI_SUM, comm);
  for (std::size_t f = 0; f < s.faults.size(); ++f)
  {
    s.faults[f].max_opening = largest[2 * f];
    s.faults[f].max_slip = largest[2 * f + 1];
    s.faults[f].closed = measure[4 * f];
    s.faults[f].slipping = measure[4 * f + 1];
    s.faults[f].stuck = measure[4 * f + 2];
    s.faults[f].moment = measure[4 * f + 3];
  }
}

/// The fault pairs' states and summaries (collective).
void fault_states(ContactState& s, const ContactMeasurement& m, MPI_Comm comm)
{
  const ContactSet& set = m.set;
  const int n = static_cast<int>(set.boundaries.size());
  std::vector<int> summary_of(n, -1);
  for (int b = 0; b < n; ++b)
    if (set.faults[b])
    {
      summary_of[b] = static_cast<int>(s.faults.size());
      s.faults.push_back({set.boundaries[b]});
    }
  if (s.faults.empty())
    return;
  std::vector<std::size_t> constraint; // of each pair
  for (std::size_t k = 0; k < set.dofs.size(); ++k)
    if (set.pair_node[k] >= 0)
    {
      s.pairs.push_back(pair_state(m, k));
      constraint.push_back(k);
    }
  summarise_faults(s, m, constraint, summary_of, comm);
}

/// The output fields of the constraints' pressures and distances; a node
/// on two foundations shows the larger pressure.
void fill_fields(const ContactMeasurement& m, double gap_scale, ContactFields out)
{
  std::span<double> pc = out.pressure.x()->mutable_array();
  std::span<double> active = out.active.x()->mutable_array();
  std::fill(pc.begin(), pc.end(), 0.0);
  std::fill(active.begin(), active.end(), 0.0);
  // A node of several constraints (two foundations, two faults' pairs where
  // they meet) shows the largest pressure, active where any is.
  std::vector<char> seen(pc.size(), 0);
  for (std::size_t k = 0; k < m.set.dofs.size(); ++k)
  {
    const std::int32_t node = m.set.output_dofs[k];
    pc[node] = seen[node] ? std::max(pc[node], m.pressure[k]) : m.pressure[k];
    const bool is_active = on_foundation(m.distance[k], gap_scale);
    active[node] = (seen[node] and active[node] > 0) or is_active ? 1.0 : 0.0;
    seen[node] = 1;
  }
  out.pressure.x()->scatter_fwd();
  out.active.x()->scatter_fwd();
}

/// The diagnostics of the constraints' pressures and distances (collective).
void summarise(ContactState& s, const ContactMeasurement& m, MPI_Comm comm)
{
  const ContactSet& set = m.set;
  double pen = -std::numeric_limits<double>::infinity(), comp = 0, force = 0;
  double pmax = -std::numeric_limits<double>::infinity(), pmin = std::numeric_limits<double>::infinity();
  int n_active = 0;
  std::vector<double> boundary_force(set.boundaries.size(), 0.0);
  std::vector<int> boundary_active(set.boundaries.size(), 0);
  for (std::size_t k = 0; k < set.dofs.size(); ++k)
  {
    const double p = m.pressure[k], distance = m.distance[k];
    const bool is_active = on_foundation(distance, s.gap_scale);
    n_active += is_active;
    boundary_force[set.boundary[k]] += p * set.lumped[k];
    boundary_active[set.boundary[k]] += is_active;
    pen = std::max(pen, -distance);
    comp = std::max(comp, std::abs(p * distance));
    pmax = std::max(pmax, p);
    pmin = std::min(pmin, p);
    force += p * set.lumped[k];
  }
  const int n_local[2] = {n_active, static_cast<int>(set.dofs.size())};
  int n_global[2];
  MPI_Allreduce(n_local, n_global, 2, MPI_INT, MPI_SUM, comm);
  s.active_nodes = n_global[0];
  s.contact_nodes = n_global[1];
  double maxes[4] = {pen, comp, pmax, -pmin}, gmax[4];
  MPI_Allreduce(maxes, gmax, 4, MPI_DOUBLE, MPI_MAX, comm);
  s.max_penetration = gmax[0];
  s.max_complementarity = gmax[1];
  s.max_pressure = gmax[2];
  s.min_pressure = -gmax[3];
  MPI_Allreduce(&force, &s.total_force, 1, MPI_DOUBLE, MPI_SUM, comm);
  const int n = static_cast<int>(set.boundaries.size());
  MPI_Allreduce(MPI_IN_PLACE, boundary_force.data(), n, MPI_DOUBLE, MPI_SUM, comm);
  MPI_Allreduce(MPI_IN_PLACE, boundary_active.data(), n, MPI_INT, MPI_SUM, comm);
  for (int b = 0; b < n; ++b)
    s.boundaries.emplace_back(set.boundaries[b], boundary_force[b], boundary_active[b]);
}
} // namespace

std::vector<double> contact_pressures(const ContactSet& set, std::span<const std::int32_t> dofs,
                                      const PetscScalar* force)
{
  std::vector<double> pressure(dofs.size());
  for (std::size_t k = 0; k < dofs.size(); ++k)
    pressure[k] = -set.sign[k] * force[dofs[k]] / set.lumped[k];
  return pressure;
}

ContactState contact_state(const ContactMeasurement& m, ContactFields out, MPI_Comm comm)
{
  ContactState s;
  s.gap_scale = m.gap_scale;
  fill_fields(m, m.gap_scale, out);
  summarise(s, m, comm);
  fault_states(s, m, comm);
  return s;
}

std::map<std::pair<std::string, std::int64_t>, double> pair_tractions(const ContactState& state)
{
  std::map<std::pair<std::string, std::int64_t>, double> traction;
  for (const PairState& pair : state.pairs)
    traction[{std::get<0>(state.boundaries[pair.fault]), pair.node}] = pair.traction;
  return traction;
}

bool same_active_set(const ActiveSet& a, const ActiveSet& b, MPI_Comm comm)
{
  int differs = a.flags != b.flags, any = 0;
  MPI_Allreduce(&differs, &any, 1, MPI_INT, MPI_MAX, comm);
  return !any;
}

} // namespace biotcontact
