#include "assembly/fault_flow.h"

#include "assembly/petsc_error.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <numeric>
#include <set>
#include <sstream>

namespace biotcontact
{
using namespace dolfinx;

std::vector<double> history_value(const FineStep& step, std::span<const double> y, std::span<const double> y_before)
{
  std::vector<double> out(y.begin(), y.end());
  const auto [c0, c1, c2] = step.c;
  for (std::size_t i = 0; i < out.size() and c2 != 0; ++i)
    out[i] = (c1 * y[i] - c2 * y_before[i]) / c0;
  return out;
}

std::vector<double> transmissibilities(std::span<const double> t, const FaultEdges& edges)
{
  std::vector<double> T(edges.size());
  for (std::size_t e = 0; e < edges.size(); ++e)
  {
    double resistance = 0;
    for (int i = 0; i < edges.width; ++i)
      resistance += edges.distances[edges.width * e + i] / t[edges.cells[edges.width * e + i]];
    T[e] = edges.measures[e] / resistance;
  }
  return T;
}

ConduitFaults::ConduitFaults(const Scene& scene, const Domain& domain, const fem::FunctionSpace& Z,
                             const FacetFlux& flux)
    : _comm(domain.mesh->comm()), _flow(*scene.flow)
{
  for (const auto& [name, b] : scene.boundaries)
    if (b.flow == BoundarySpec::Flow::pressure)
      _pressure_boundaries[name] = &b.pressure;
  const int d = _dim = domain.dim();
  for (const auto& [name, f] : scene.faults)
  {
    if (f.flow != FaultFlow::conduit)
      continue;
    const FaultCells& cells = domain.faults.at(name).cells;
    const double resistance = std::isinf(f.normal_permeability) ? 0.0 : _flow.mu_f / (2 * f.normal_permeability);
    const std::vector<double> w_r(cells.size(), f.residual_aperture), zero(cells.size(), 0.0);
    _conduits.push_back({name, _size, &cells, w_r, w_r, w_r, f.residual_aperture, f.closure,
                         scene.mechanics ? softest_modulus(scene) : 0.0, std::vector<char>(cells.size(), 0),
                         std::vector<char>(cells.size(), 0), zero, zero, resistance, f.permeability});
    std::map<std::vector<std::int64_t>, std::int64_t> index;
    for (std::size_t k = 0; k < cells.size(); ++k)
      index[{cells.keys.begin() + d * k, cells.keys.begin() + d * (k + 1)}] = static_cast<std::int64_t>(k);
    for (const FaceRow& r : fault_face_rows(domain, Z, name, flux(domain.fault_faces(name))))
      _faces.push_back({r.dof, _conduits.size() - 1, index.at(r.key), r.flux});
    locate_wells(scene, name, cells, _size);
    _size += static_cast<std::int64_t>(cells.size());
  }
  std::vector<const FaultCells*> cells;
  for (const Conduit& c : _conduits)
    cells.push_back(c.cells);
  FaultNetwork network = fault_network(cells);
  for (std::size_t i = 0; i < _conduits.size(); ++i)
    _conduits[i].links = std::move(network.links[i]);
  _junctions = std::move(network.junctions);
  _through.assign(_junctions.size(), 0.0);
  _start = Z.dofmap()->index_map->local_range()[0];
  _rows = fault_rows(scene, domain);
}

void ConduitFaults::locate_wells(const Scene& scene, const std::string& fault, const FaultCells& cells,
                                 std::int64_t offset)
{
  for (const auto& [name, w] : scene.wells)
    if (w.fault == fault)
    {
      const WellOnFault hit = well_cells(cells, w);
      for (std::size_t i = 0; i < hit.cells.size(); ++i)
        _wells.push_back({offset + hit.cells[i], hit.shares[i], &w.rate, _conduits.size() - 1});
    }
}

std::vector<double> ConduitFaults::initial_pressure(const Expression& p0) const
{
  std::vector<double> p;
  for (const Conduit& c : _conduits)
    for (std::size_t k = 0; k < c.cells->size(); ++k)
      p.push_back(p0(c.cells->centroids[k].data(), 0.0));
  return _rows.entries(p);
}

Mat ConduitFaults::exchange(PetscInt flow_rows) const
{
  Mat B = nullptr;
  check_petsc(MatCreateAIJ(_comm, _rows.owned(), flow_rows, PETSC_DETERMINE, PETSC_DETERMINE, 2, nullptr, 2, nullptr,
                           &B),
              "the conduit faults' exchange matrix: MatCreateAIJ");
  check_petsc(MatSetOption(B, MAT_NEW_NONZERO_ALLOCATION_ERR, PETSC_FALSE),
              "the conduit faults' exchange matrix: MatSetOption");
  for (const Face& f : _faces)
    check_petsc(MatSetValue(B, _rows.row[_conduits[f.conduit].offset + f.cell], static_cast<PetscInt>(f.dof), f.flux,
                            INSERT_VALUES),
                "the conduit faults' exchange matrix: MatSetValue");
  check_petsc(MatAssemblyBegin(B, MAT_FINAL_ASSEMBLY), "the conduit faults' exchange matrix: MatAssemblyBegin");
  check_petsc(MatAssemblyEnd(B, MAT_FINAL_ASSEMBLY), "the conduit faults' exchange matrix: MatAssemblyEnd");
  return B;
}

std::vector<std::pair<PetscInt, double>> ConduitFaults::face_resistance() const
{
  std::vector<std::pair<PetscInt, double>> rows;
  for (const Face& f : _faces)
    if (const Conduit& c = _conduits[f.conduit]; c.normal_resistance > 0)
      rows.emplace_back(static_cast<PetscInt>(f.dof),
                        c.normal_resistance * c.aperture[f.cell] * f.flux * f.flux / c.cells->measures[f.cell]);
  return rows;
}

std::vector<double> ConduitFaults::storage(const Conduit& c, double dt) const
{
  std::vector<double> s(c.cells->size());
  for (std::size_t k = 0; k < s.size(); ++k)
    s[k] = c.aperture[k] * _flow.c_f * c.cells->measures[k] / dt;
  return s;
}

std::vector<double> ConduitFaults::opening_rates(const FineStep& step, std::span<const double> p_old,
                                                 std::span<const double> p_iterate) const
{
  const std::vector<double> p_star = pressure_history(step, _rows.everywhere(p_old));
  const std::vector<double> p = _rows.everywhere(p_iterate);
  std::vector<double> rates;
  for (const Conduit& c : _conduits)
    for (std::size_t k = 0; k < c.open.size(); ++k)
    {
      const std::size_t row = c.offset + k;
      rates.push_back(c.open[k] ? -c.cells->measures[k] / step.dt * (1 + _flow.c_f * (p[row] - p_star[row])) : 0.0);
    }
  return _rows.entries(rates);
}

std::vector<double> ConduitFaults::pressure_history(const FineStep& step, std::span<const double> p_old) const
{
  return history_value(step, p_old, _pressure_before.empty() ? p_old : std::span<const double>(_pressure_before));
}

std::vector<double> ConduitFaults::conductance(const Conduit& c) const
{
  // Before the first mechanics iterate (or without mechanics) w_h itself.
  const std::vector<double>& w = c.conducting.empty() ? c.aperture : c.conducting;
  std::vector<double> t(w.size());
  for (std::size_t k = 0; k < t.size(); ++k)
    t[k] = c.permeability > 0 ? c.permeability * w[k] / _flow.mu_f : std::pow(w[k], 3) / (12 * _flow.mu_f);
  return t;
}

std::vector<ConduitFaults::JunctionLink> ConduitFaults::junction_links() const
{
  // The intersection's pressure p_j, eliminated from sum_i h_i (p_i - p_j) =
  // 0, leaves between each two members the transmissibility h_a h_b / sum_i
  // h_i (a star-delta transform: exact). Member i reaches the intersection
  // through half its cell and the intersection's own resistance r_j, the
  // mean of mu_f / (2 k_n) over the faults that meet there (their normal
  // permeabilities' harmonic mean): 1/h_i = (d_i / t_i + r_j) / |e|.
  std::vector<std::vector<double>> t;
  for (const Conduit& c : _conduits)
    t.push_back(conductance(c));
  std::vector<JunctionLink> links;
  for (const FaultJunction& j : _junctions)
  {
    const auto index = static_cast<std::size_t>(&j - _junctions.data());
    const double r = junction_resistance(j);
    std::vector<double> h;
    for (std::size_t i = 0; i < j.cells.size(); ++i)
      h.push_back(j.measure / (j.distances[i] / t[j.faults[i]][j.cells[i]] + r));
    const double sum = std::accumulate(h.begin(), h.end(), 0.0);
    for (std::size_t a = 0; a < h.size(); ++a)
      for (std::size_t b = a + 1; b < h.size(); ++b)
        links.push_back({{_conduits[j.faults[a]].offset + j.cells[a], _conduits[j.faults[b]].offset + j.cells[b]},
                         {j.faults[a], j.faults[b]}, h[a] * h[b] / sum, &j.point, index});
  }
  return links;
}

double ConduitFaults::junction_resistance(const FaultJunction& j) const
{
  std::set<std::size_t> faults(j.faults.begin(), j.faults.end());
  double r = 0;
  for (std::size_t f : faults)
    r += _conduits[f].normal_resistance / static_cast<double>(faults.size());
  return r;
}

std::pair<std::vector<std::size_t>, std::vector<double>> ConduitFaults::held_ends(const Conduit& c) const
{
  const std::vector<double> T = transmissibilities(conductance(c), c.cells->ends);
  std::pair<std::vector<std::size_t>, std::vector<double>> held;
  for (std::size_t e = 0; e < T.size(); ++e)
    if (_pressure_boundaries.count(c.cells->end_groups[e]))
      held.first.push_back(e), held.second.push_back(T[e]);
  return held;
}

std::vector<double> ConduitFaults::end_pressures(const Conduit& c, const std::vector<std::size_t>& held,
                                                 double t) const
{
  std::vector<double> p;
  for (std::size_t e : held)
    p.push_back((*_pressure_boundaries.at(c.cells->end_groups[e]))(c.cells->ends.points[e].data(), t));
  return p;
}

Mat ConduitFaults::operator_matrix(double dt) const
{
  Mat C = nullptr;
  const std::int32_t owned = _rows.owned();
  check_petsc(MatCreateAIJ(_comm, owned, owned, PETSC_DETERMINE, PETSC_DETERMINE, 8, nullptr, 8, nullptr, &C),
              "the conduit faults' matrix: MatCreateAIJ");
  // 8 per row is a guess: a cell by a junction couples to every member of
  // its star (four faults through one point: 9 entries).
  check_petsc(MatSetOption(C, MAT_NEW_NONZERO_ALLOCATION_ERR, PETSC_FALSE),
              "the conduit faults' matrix: MatSetOption");
  // Each rank sets its own rows: (cell k, cell l, value).
  auto add = [&](std::int64_t k, std::int64_t l, double v)
  {
    if (_rows.owns(k))
      check_petsc(MatSetValue(C, _rows.row[k], _rows.row[l], v, ADD_VALUES), "the conduit faults' matrix: MatSetValue");
  };
  for (const Conduit& c : _conduits)
  {
    const std::int64_t o = c.offset;
    std::vector<double> diagonal = storage(c, dt);
    const std::vector<double> L = stabilisation(c, dt);
    std::transform(diagonal.begin(), diagonal.end(), L.begin(), diagonal.begin(),
                   [](double s, double l) { return -s - l; });
    const std::vector<double> T = transmissibilities(conductance(c), c.links);
    for (std::size_t e = 0; e < T.size(); ++e)
    {
      const std::int64_t k = o + c.links.cells[2 * e], l = o + c.links.cells[2 * e + 1];
      add(k, k, -T[e]), add(k, l, T[e]), add(l, k, T[e]), add(l, l, -T[e]);
    }
    const auto [held, T_e] = held_ends(c);
    for (std::size_t i = 0; i < held.size(); ++i)
      diagonal[c.cells->ends.cells[held[i]]] -= T_e[i];
    for (std::size_t k = 0; k < diagonal.size(); ++k)
      add(o + static_cast<std::int64_t>(k), o + static_cast<std::int64_t>(k), diagonal[k]);
  }
  for (const JunctionLink& j : junction_links())
  {
    const auto [k, l] = j.rows;
    add(k, k, -j.T), add(k, l, j.T), add(l, k, j.T), add(l, l, -j.T);
  }
  check_petsc(MatAssemblyBegin(C, MAT_FINAL_ASSEMBLY), "the conduit faults' matrix: MatAssemblyBegin");
  check_petsc(MatAssemblyEnd(C, MAT_FINAL_ASSEMBLY), "the conduit faults' matrix: MatAssemblyEnd");
  return C;
}

void ConduitFaults::begin_step()
{
  for (Conduit& c : _conduits)
  {
    std::fill(c.open.begin(), c.open.end(), 0);
    c.flips.assign(c.open.size(), 0);
    c.pins.assign(c.open.size(), 0);
    c.opening.assign(c.open.size(), 0.0);
    if (!c.conducting.empty()) // the step starts from w_h, as a restart does
      c.conducting = c.aperture;
  }
  _relaxing = _lagged = _newton = _held = _overshot = false;
  _relaxation = 1;
  _stalled = 0;
  _lags.clear();
}

bool ConduitFaults::set_openings(std::span<const double> opening, std::span<const double> traction)
{
  bool changed = false, flipped_back = false;
  double largest = 0, change = 0;
  for (Conduit& c : _conduits)
    for (std::size_t k = 0; k < c.aperture.size(); ++k)
    {
      const double e = open_fraction * c.residual, w = opening[c.offset + k];
      if (c.closure and !traction.empty()) // none before the first mechanics solve: the unloaded u = 0
        c.traction[k] = traction[c.offset + k];
      const int pin = c.pins.empty() ? 0 : c.pins[k];
      if (!c.opening.empty())
        c.opening[k] = w;
      const double w_h = c.residual + (c.closure ? closure_aperture(*c.closure, c.traction[k]) : 0.0)
                         + (pin < 0 ? w - e : pin > 0 ? 0.0 : std::max(w - e, 0.0));
      const char open = pin < 0 or (pin == 0 and w > e);
      if (!c.flips.empty() and open != c.open[k])
        ++c.flips[k];
      flipped_back = flipped_back or (_lagged and pin == 0 and open != c.open[k] and open == c.open_before[k]);
      changed = changed or w_h != c.aperture[k] or (open or c.open[k]) != (c.open[k] or c.open_before[k]);
      largest = std::max(largest, w_h);
      change = open != c.open[k] ? INFINITY : std::max(change, std::abs(w_h - c.aperture[k]));
      c.aperture[k] = w_h;
      c.open_before[k] = c.open[k];
      c.open[k] = open;
    }
  for (Conduit& c : _conduits)
  {
    set_compliance(c);
    if (!_started)
      c.aperture_start = c.aperture_before = c.aperture;
  }
  _started = true;
  _relaxing = _relaxing or flipped_back;
  const double moved = relax_conducting();
  _aperture_change = std::max(change, moved) / largest;
  return changed or moved > 0;
}

double ConduitFaults::relax_conducting()
{
  // The fixed point conducting = w_h(u(conducting)), r = w_h - conducting
  // its lag: taken whole (omega = 1) until a cell's open state flips back
  // (set_openings: the cubic law cycling, an open cell sheds its fluid and
  // closes, then fills and opens again) or until the lag shrinks by less
  // than relaxed_above (the monolithic step, whose open cells move with p_f
  // in one solve; the split, where an open cell's lagged w_h^3 can move p_f
  // more than its fixed-stress term holds: a 2-cycle); from then to the
  // step's end by Aitken's factor, omega = -omega (r_old . (r - r_old)) /
  // |r - r_old|^2, clamped to [1e-3, 1]. A negative factor (the map
  // amplifies the lag's mode: the opening spreads) would step back against
  // the lag: the monolithic step then takes the lag whole with Newton's
  // term of the transmissibilities (newton(), flux_jacobian), the split the
  // factor's magnitude (held at the floor its apertures crawled), unless
  // the lag is below the openings' round-off, where the factor's sign is
  // noise and the floor holds the fixed point. There, in the split, a lag
  // that stagnates (stagnant: Aitken's factor computed from noise, cycling
  // with period 4) is held at the floor to the step's end; the monolithic
  // step, whose stopping test holds the lag, relaxes it on. Newton's term
  // is dropped for the step's rest where the lag grows under it above that
  // round-off (its step on the cubic law overshot), back to the factor
  // before it (theory.md, "Flow in a fault").
  double dot = 0, norm = 0, lag = 0, lag_old = 0, moved = 0, round_off = 0;
  for (Conduit& c : _conduits)
  {
    round_off = std::max(round_off, open_fraction * c.residual); // as set_openings's
    if (c.conducting.empty())
      c.conducting = c.aperture, c.lag.assign(c.aperture.size(), 0.0);
    for (std::size_t k = 0; k < c.aperture.size(); ++k)
    {
      const double r = c.aperture[k] - c.conducting[k], d = r - c.lag[k];
      dot += c.lag[k] * d, norm += d * d, lag += r * r, lag_old += c.lag[k] * c.lag[k];
    }
  }
  // The split's lag shrinks at the coupling's rate, after a transient: there
  // only a lag that grew at stalled_iterations iterations in a row counts.
  // The monolithic step's first lag grew from none (w_c = w_h at the start):
  // it relaxes from there, by Aitken's factor 0 (no lag before), the floor,
  // a cautious first move the opening needs (taken whole, fault_reactivation
  // opened at 1e-3 m^2/s cycles with period 3 in its first step).
  const bool stalled = _lagged and lag > (_implicit ? relaxed_above * relaxed_above : 1.0) * lag_old;
  _stalled = stalled ? _stalled + 1 : 0;
  _relaxing = _relaxing or _stalled >= (_implicit ? 1 : stalled_iterations);
  if (_newton and stalled and std::sqrt(lag) > round_off)
    _newton = false, _overshot = true, _relaxation = _relaxed;
  else if (_relaxing and norm > 0 and !_newton)
  {
    const double aitken = -_relaxation * dot / norm;
    _newton = _implicit and aitken < 0 and !_overshot;
    _relaxed = _relaxation;
    const bool noise = std::sqrt(lag) <= round_off;
    _relaxation = _newton ? 1.0 : std::clamp(noise ? aitken : std::abs(aitken), 1e-3, 1.0);
    _held = _held or (noise and stagnant(std::sqrt(lag)) and !_implicit);
    _relaxation = _held ? 1e-3 : _relaxation;
  }
  _lags.push_back(std::sqrt(lag));
  for (Conduit& c : _conduits)
    for (std::size_t k = 0; k < c.aperture.size(); ++k)
    {
      c.lag[k] = c.aperture[k] - c.conducting[k];
      c.conducting[k] += _relaxation * c.lag[k];
      moved = std::max(moved, std::abs(c.lag[k]));
    }
  _lagged = true;
  return moved;
}

void ConduitFaults::drop_newton()
{
  // The last relax_conducting took the lag whole (omega = 1).
  for (Conduit& c : _conduits)
    for (std::size_t k = 0; k < c.conducting.size(); ++k)
      c.conducting[k] -= (1 - _relaxed) * c.lag[k];
  _newton = false, _overshot = true, _relaxation = _relaxed;
}

bool ConduitFaults::stagnant(double lag) const
{
  const std::size_t n = _lags.size();
  return n >= lag_window and lag > 0.5 * _lags[n - lag_window];
}

void ConduitFaults::load(const FineStep& step, std::span<const double> p_old, std::span<const double> p_iterate,
                         std::span<double> b) const
{
  // Every cell's entry on every rank (few), then this rank's.
  const std::vector<double> p_star = pressure_history(step, _rows.everywhere(p_old));
  const std::vector<double> p = _rows.everywhere(p_iterate);
  std::vector<double> all(_rows.size(), 0.0);
  for (const Conduit& c : _conduits)
  {
    const std::vector<double> s = storage(c, step.dt), L = stabilisation(c, step.dt);
    const std::vector<double> w_star = history_value(step, c.aperture_start, c.aperture_before);
    for (std::size_t k = 0; k < s.size(); ++k)
      all[c.offset + k] = -s[k] * p_star[c.offset + k] - L[k] * p[c.offset + k]
                          + c.cells->measures[k] * (c.aperture[k] - w_star[k]) / (step.q * step.dt);
    const auto [held, T_e] = held_ends(c);
    const std::vector<double> p_D = end_pressures(c, held, step.t);
    for (std::size_t i = 0; i < held.size(); ++i)
      all[c.offset + c.cells->ends.cells[held[i]]] -= T_e[i] * p_D[i];
  }
  for (const Well& w : _wells)
    all[w.row] -= w.share * (*w.rate)(0, 0, 0, step.t);
  const std::vector<double> mine = _rows.entries(all);
  std::copy(mine.begin(), mine.end(), b.begin());
}

std::vector<double> ConduitFaults::mean_flux(const Conduit& c, std::span<const double> pressure,
                                             const std::vector<JunctionLink>& links, double t) const
{
  const FaultCells& cells = *c.cells;
  const std::span<const double> p = pressure.subspan(c.offset, cells.size());
  std::vector<double> q(3 * cells.size(), 0.0);
  auto add = [&](std::int64_t k, double F, const std::array<double, 3>& m)
  {
    for (int i = 0; i < 3; ++i)
      q[3 * k + i] += F * (m[i] - cells.centroids[k][i]);
  };
  const std::vector<double> T = transmissibilities(conductance(c), c.links);
  for (std::size_t e = 0; e < T.size(); ++e)
  {
    const std::int64_t k = c.links.cells[2 * e], l = c.links.cells[2 * e + 1];
    const double F = T[e] * (p[k] - p[l]);
    add(k, F, c.links.points[e]);
    add(l, -F, c.links.points[e]);
  }
  const auto self = static_cast<std::size_t>(&c - _conduits.data());
  for (const JunctionLink& j : links)
  {
    const double F = j.T * (pressure[j.rows[0]] - pressure[j.rows[1]]);
    for (int side = 0; side < 2; ++side)
      if (j.conduits[side] == self)
        add(j.rows[side] - c.offset, side == 0 ? F : -F, *j.point);
  }
  const auto [held, T_e] = held_ends(c);
  const std::vector<double> p_D = end_pressures(c, held, t);
  for (std::size_t i = 0; i < held.size(); ++i)
  {
    const std::int64_t k = cells.ends.cells[held[i]];
    add(k, T_e[i] * (p[k] - p_D[i]), cells.ends.points[held[i]]);
  }
  for (std::size_t k = 0; k < cells.size(); ++k)
    for (int i = 0; i < 3; ++i)
      q[3 * k + i] /= cells.measures[k];
  return q;
}

std::vector<double> ConduitFaults::cell_values(std::span<const double> w, std::span<const double> p, double t) const
{
  // Per face: the cell's index, the exchange's bits.
  std::vector<std::int64_t> rows;
  for (const Face& f : _faces)
    for (std::int64_t v : {_conduits[f.conduit].offset + f.cell, std::bit_cast<std::int64_t>(f.flux * w[f.dof - _start])})
      rows.push_back(v);
  const Gathered all = all_gather(rows, _comm);
  const std::vector<double> pressure = _rows.everywhere(p);
  if (_rows.rank != 0)
    return {};
  std::vector<double> values(6 * _rows.size(), 0.0);
  for (std::size_t r = 0; r < all.values.size(); r += 2)
    values[6 * all.values[r] + 2] += std::bit_cast<double>(all.values[r + 1]);
  const std::vector<JunctionLink> links = junction_links();
  for (const Conduit& c : _conduits)
  {
    const std::span<const double> p_c(pressure.data() + c.offset, c.cells->size());
    const std::vector<double> q = mean_flux(c, pressure, links, t);
    for (std::size_t k = 0; k < c.cells->size(); ++k)
    {
      double* row = &values[6 * (c.offset + k)];
      row[0] = p_c[k], row[1] = c.aperture[k], row[2] /= c.cells->measures[k];
      std::copy_n(&q[3 * k], 3, row + 3);
    }
  }
  return values;
}

} // namespace biotcontact
