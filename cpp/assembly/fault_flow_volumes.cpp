// The volume bookkeeping of the conduit faults (ConduitFaults, fault_flow.h):
// each step's volumes of each fault, their balance, their sums since the
// start and the rates through the intersections (fault_volumes.h); and what
// a checkpoint keeps of the faults between steps. Twin:
// python_prototype/assembly/fault_flow_volumes.py.
#include "assembly/fault_flow.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <set>
#include <sstream>
#include <utility>

namespace biotcontact
{

std::vector<StepVolumes> ConduitFaults::step_volumes(std::span<const double> w, std::span<const double> p_mine,
                                                     std::span<const double> p_old, const FineStep& fine) const
{
  // BDF2 balances its derivative, c0 (y - y*)/dt_n, against the rates over
  // the step dt_n = c0 fine.dt: stored = c0 (y - y*) (time_scheme.h).
  const double t = fine.t, c0 = fine.c[0], dt = c0 * fine.dt;
  const std::vector<double> p_star = pressure_history(fine, _rows.everywhere(p_old));
  const std::vector<double> p = _rows.everywhere(p_mine);
  // Per fault: injected, stored, exchanged, outflow of the step, gross,
  // held and faces; the faces on the ranks that own them, the rest by each
  // cell's owner (a junction's link by its first member's). The
  // intersections in the 8th column.
  std::vector<double> step(8 * _conduits.size(), 0.0);
  auto add = [&](std::size_t i, int column, double v) { step[8 * i + column] += v, step[8 * i + 4] += std::abs(v); };
  for (const Face& f : _faces)
  {
    add(f.conduit, 2, dt * f.flux * w[f.dof - _start]);
    step[8 * f.conduit + 6] += dt * std::abs(f.flux);
  }
  for (const Well& well : _wells)
    if (_rows.owns(well.row))
      add(well.conduit, 0, dt * well.share * (*well.rate)(0, 0, 0, t));
  for (std::size_t i = 0; i < _conduits.size(); ++i)
  {
    const Conduit& c = _conduits[i];
    const std::vector<double>& measures = c.cells->measures;
    const std::vector<double> w_star = history_value(fine, c.aperture_start, c.aperture_before);
    for (std::size_t k = 0; k < measures.size(); ++k)
    {
      if (!_rows.owns(c.offset + static_cast<std::int64_t>(k)))
        continue;
      add(i, 1, c0 * measures[k] * (c.aperture[k] - w_star[k]) / fine.q
                    + c0 * _flow.c_f * c.aperture[k] * measures[k] * (p[c.offset + k] - p_star[c.offset + k]));
      step[8 * i + 5] += measures[k] * c.aperture[k];
    }
    const auto [held, T_e] = held_ends(c);
    const std::vector<double> p_D = end_pressures(c, held, t);
    for (std::size_t e = 0; e < held.size(); ++e)
      if (_rows.owns(c.offset + c.cells->ends.cells[held[e]]))
        add(i, 3, dt * T_e[e] * (p[c.offset + c.cells->ends.cells[held[e]]] - p_D[e]));
  }
  for (const JunctionLink& j : junction_links())
    if (j.conduits[0] != j.conduits[1] and _rows.owns(j.rows[0])) // from the first member's fault into the second's
    {
      const double V = dt * j.T * (p[j.rows[0]] - p[j.rows[1]]);
      add(j.conduits[0], 7, -V);
      add(j.conduits[1], 7, V);
    }
  MPI_Allreduce(MPI_IN_PLACE, step.data(), static_cast<int>(step.size()), MPI_DOUBLE, MPI_SUM, _comm);
  std::vector<StepVolumes> volumes(_conduits.size());
  for (std::size_t i = 0; i < _conduits.size(); ++i)
  {
    const double* s = &step[8 * i];
    volumes[i] = {{s[0], s[1], s[2], s[3], s[7]}, s[4], s[5], s[6]};
  }
  return volumes;
}

std::string ConduitFaults::unbalanced(const std::vector<StepVolumes>& step, double rock_flux) const
{
  for (std::size_t i = 0; i < _conduits.size(); ++i)
  {
    const FaultVolumes& s = step[i].net;
    const FaultVolumes& v = _conduits[i].volumes;
    const FaultVolumes total{v.injected + s.injected, v.stored + s.stored, v.exchanged + s.exchanged,
                             v.outflow + s.outflow, v.intersections + s.intersections};
    const double imbalance = volume_imbalance(step[i], total, rock_flux);
    if (!(imbalance <= volume_balance_tolerance)) // NaN too
    {
      std::ostringstream line;
      const bool network = !_junctions.empty();
      line << "fault." << _conduits[i].name << ": its volumes do not balance: injected + exchanged"
           << (network ? " + intersections" : "") << " - stored - outflow = "
           << s.injected + s.exchanged + s.intersections - s.stored - s.outflow << " in the step (injected "
           << s.injected << ", exchanged " << s.exchanged;
      if (network)
        line << ", intersections " << s.intersections;
      line << ", stored " << s.stored << ", outflow " << s.outflow << "), " << imbalance
           << " of the volumes, more than " << volume_balance_tolerance;
      return line.str();
    }
  }
  return {};
}

void ConduitFaults::add_volumes(const std::vector<StepVolumes>& step, const FineStep& fine,
                                std::span<const double> p_start)
{
  if (fine.m == fine.q)
    _pressure_before = _rows.everywhere(p_start);
  for (std::size_t i = 0; i < _conduits.size(); ++i)
  {
    FaultVolumes& v = _conduits[i].volumes;
    const FaultVolumes& s = step[i].net;
    v.injected += s.injected, v.stored += s.stored, v.exchanged += s.exchanged, v.outflow += s.outflow;
    v.intersections += s.intersections;
    if (fine.m == fine.q)
      _conduits[i].aperture_before = std::exchange(_conduits[i].aperture_start, _conduits[i].aperture);
  }
}

void ConduitFaults::set_intersection_rates(std::span<const double> p_mine)
{
  // Each member's net flow into the junction, sum_b T_ab (p_a - p_b) over
  // its links there; the positive ones summed are what passes through
  // (every rank alike, from every cell's p).
  _through.assign(_junctions.size(), 0.0);
  if (_junctions.empty()) // the same on every rank
    return;
  const std::vector<double> p = _rows.everywhere(p_mine);
  std::map<std::pair<std::size_t, std::int64_t>, double> into; // (junction, row)
  for (const JunctionLink& j : junction_links())
  {
    const double q = j.T * (p[j.rows[0]] - p[j.rows[1]]);
    into[{j.junction, j.rows[0]}] += q;
    into[{j.junction, j.rows[1]}] -= q;
  }
  for (const auto& [key, q] : into)
    _through[key.first] += std::max(q, 0.0);
}

std::vector<IntersectionRate> ConduitFaults::intersection_rates() const
{
  std::map<std::vector<std::string>, IntersectionRate> by_faults;
  for (std::size_t j = 0; j < _junctions.size(); ++j)
  {
    std::vector<std::string> names;
    for (std::size_t f : std::set<std::size_t>(_junctions[j].faults.begin(), _junctions[j].faults.end()))
      names.push_back(_conduits[f].name);
    IntersectionRate& r = by_faults[names];
    r.faults = names;
    r.junctions += 1;
    r.rate += _through[j];
  }
  std::vector<IntersectionRate> rates;
  for (const auto& [names, r] : by_faults)
    rates.push_back(r);
  return rates;
}

std::vector<std::pair<std::string, FaultVolumes>> ConduitFaults::volumes() const
{
  std::vector<std::pair<std::string, FaultVolumes>> v;
  for (const Conduit& c : _conduits)
    v.emplace_back(c.name, c.volumes);
  return v;
}

std::vector<double> ConduitFaults::volume_values() const
{
  std::vector<double> values;
  for (const Conduit& c : _conduits)
    values.insert(values.end(), {c.volumes.injected, c.volumes.stored, c.volumes.exchanged, c.volumes.outflow,
                                 c.volumes.intersections});
  return values;
}

void ConduitFaults::set_volume_values(std::span<const double> values)
{
  // Five per fault (four in the checkpoints before the intersections).
  const std::size_t n = _conduits.empty() ? 5 : values.size() / _conduits.size();
  for (std::size_t i = 0; i < _conduits.size(); ++i)
    _conduits[i].volumes = {values[n * i], values[n * i + 1], values[n * i + 2], values[n * i + 3],
                            n > 4 ? values[n * i + 4] : 0.0};
}

std::vector<double> ConduitFaults::start_apertures() const
{
  std::vector<double> w_h;
  for (const Conduit& c : _conduits)
    w_h.insert(w_h.end(), c.aperture_start.begin(), c.aperture_start.end());
  return w_h;
}

void ConduitFaults::set_start_apertures(std::span<const double> w_h)
{
  for (Conduit& c : _conduits)
    std::copy_n(w_h.begin() + c.offset, c.aperture_start.size(), c.aperture_start.begin());
  _started = true;
}

std::map<std::string, std::vector<double>> ConduitFaults::arrays(std::span<const double> p) const
{
  // Every cell on every rank.
  std::vector<double> before, pressure = _rows.everywhere(p);
  for (const Conduit& c : _conduits)
    before.insert(before.end(), c.aperture_before.begin(), c.aperture_before.end());
  return {{"fault_pressure", pressure},
          {"fault_volumes", volume_values()},
          {"fault_apertures", start_apertures()},
          {"fault_pressure_before", _pressure_before.empty() ? pressure : _pressure_before},
          {"fault_apertures_before", before}};
}

void ConduitFaults::restore_arrays(const std::map<std::string, std::vector<double>>& arrays, std::span<double> p)
{
  const std::vector<double>& pressure = arrays.at("fault_pressure"); // every cell
  const std::vector<double> mine = _rows.entries(pressure);
  std::copy(mine.begin(), mine.end(), p.begin());
  set_volume_values(arrays.at("fault_volumes"));
  if (const auto found = arrays.find("fault_apertures"); found != arrays.end())
    set_start_apertures(found->second);
  // Checkpoints before BDF2's conduits have neither: the step before is
  // then the start's (only backward Euler reads them there).
  const auto found_before = arrays.find("fault_pressure_before");
  _pressure_before = found_before == arrays.end() ? pressure : found_before->second;
  const auto found = arrays.find("fault_apertures_before");
  for (Conduit& c : _conduits)
    c.aperture_before = found == arrays.end() ? c.aperture_start
                                              : std::vector<double>(found->second.begin() + c.offset,
                                                                    found->second.begin() + c.offset
                                                                        + static_cast<std::int64_t>(c.aperture_start.size()));
}

} // namespace biotcontact
