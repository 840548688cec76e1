// Newton's term of the conduit faults' transmissibilities (fault_flow_jacobian.h)
// and ConduitFaults' methods that assemble it (fault_flow.h): the derivative
// of each cell's flux terms by the conducting apertures of the open cells,
// which the monolithic step's rows carry so that its aperture iteration is
// a Newton iteration on the cubic law. Twin:
// python_prototype/assembly/fault_flow_jacobian.py.
#include "assembly/fault_flow_jacobian.h"
#include "assembly/fault_flow.h"
#include "assembly/petsc_error.h"

#include <numeric>

namespace biotcontact
{

namespace
{
/// check_petsc for the Jacobian's calls (MatSetValue runs once per link).
void check_jacobian(PetscErrorCode code, const char* call) { check_petsc(code, "the conduit faults' Jacobian", call); }
} // namespace

std::vector<double> transmissibility_slopes(std::span<const double> t, std::span<const double> slope,
                                           const FaultEdges& edges)
{
  std::vector<double> dT(edges.cells.size());
  for (std::size_t e = 0; e < edges.size(); ++e)
  {
    double R = 0;
    for (int i = 0; i < edges.width; ++i)
      R += edges.distances[edges.width * e + i] / t[edges.cells[edges.width * e + i]];
    for (int i = 0; i < edges.width; ++i)
    {
      const std::size_t n = edges.width * e + i;
      const auto k = static_cast<std::size_t>(edges.cells[n]);
      dT[n] = edges.measures[e] * edges.distances[n] * slope[k] / (R * R * t[k] * t[k]);
    }
  }
  return dT;
}

std::vector<double> star_flux_derivative(std::span<const double> h, std::span<const double> p)
{
  const double S = std::accumulate(h.begin(), h.end(), 0.0);
  const double p_j = std::inner_product(h.begin(), h.end(), p.begin(), 0.0) / S;
  const std::size_t n = h.size();
  std::vector<double> dN(n * n);
  for (std::size_t a = 0; a < n; ++a)
    for (std::size_t c = 0; c < n; ++c)
      dN[n * a + c] = (a == c ? -(p[a] - p_j) : 0.0) + h[a] * (p[c] - p_j) / S;
  return dN;
}

std::vector<double> ConduitFaults::conductance_slope(const Conduit& c) const
{
  // t = k_f w / mu_f (dt/dw = t/w) or w^3 / (12 mu_f) (dt/dw = 3 t/w), at
  // the conducting aperture; 0 in closed cells, whose w_h does not move
  // with u (a closure's moves with s_n, explicit), and before newton().
  const std::vector<double>& w = c.conducting.empty() ? c.aperture : c.conducting;
  const std::vector<double> t = conductance(c);
  std::vector<double> slope(t.size(), 0.0);
  for (std::size_t k = 0; k < t.size(); ++k)
    if (c.open[k] and newton())
      slope[k] = (c.permeability > 0 ? 1.0 : 3.0) * t[k] / w[k];
  return slope;
}

Mat ConduitFaults::flux_jacobian(std::span<const double> p_mine, double t) const
{
  const std::vector<double> p = _rows.everywhere(p_mine);
  Mat D = nullptr;
  check_jacobian(MatCreateAIJ(_comm, _rows.owned(), _rows.owned(), PETSC_DETERMINE, PETSC_DETERMINE, 8, nullptr, 8,
                              nullptr, &D),
                 "MatCreateAIJ");
  // 8 per row is a guess, as in operator_matrix (a junction's star).
  check_jacobian(MatSetOption(D, MAT_NEW_NONZERO_ALLOCATION_ERR, PETSC_FALSE), "MatSetOption");
  // Each rank sets its own rows: (cell k, cell m, value).
  auto add = [&](std::int64_t k, std::int64_t m, double v)
  {
    if (_rows.owns(k))
      check_jacobian(MatSetValue(D, _rows.row[k], _rows.row[m], v, ADD_VALUES), "MatSetValue");
  };
  for (std::int64_t k = 0; k < _size; ++k)
    add(k, k, 0.0); // every diagonal entry: B = (rates + D) J's structure stays
  for (const Conduit& c : _conduits)
  {
    const std::int64_t o = c.offset;
    const std::vector<double> t_c = conductance(c), slope = conductance_slope(c);
    // A link's N_k = -T (p_k - p_l), N_l = -T (p_l - p_k); entries kept
    // where closed (their slope 0).
    const std::vector<double> dT = transmissibility_slopes(t_c, slope, c.links);
    for (std::size_t e = 0; e < c.links.size(); ++e)
    {
      const std::array<std::int64_t, 2> kl{o + c.links.cells[2 * e], o + c.links.cells[2 * e + 1]};
      const double jump = p[kl[0]] - p[kl[1]];
      for (int i = 0; i < 2; ++i)
        add(kl[0], kl[i], -dT[2 * e + i] * jump), add(kl[1], kl[i], dT[2 * e + i] * jump);
    }
    // An end's N_k = -T_e (p_k - p_D).
    const std::vector<double> dT_e = transmissibility_slopes(t_c, slope, c.cells->ends);
    const auto [held, T_e] = held_ends(c);
    const std::vector<double> p_D = end_pressures(c, held, t);
    for (std::size_t i = 0; i < held.size(); ++i)
    {
      const std::int64_t k = o + c.cells->ends.cells[held[i]];
      add(k, k, -dT_e[held[i]] * (p[k] - p_D[i]));
    }
  }
  add_junction_jacobian(p, D);
  check_jacobian(MatAssemblyBegin(D, MAT_FINAL_ASSEMBLY), "MatAssemblyBegin");
  check_jacobian(MatAssemblyEnd(D, MAT_FINAL_ASSEMBLY), "MatAssemblyEnd");
  return D;
}

void ConduitFaults::add_junction_jacobian(std::span<const double> p, Mat D) const
{
  // Member c reaches the junction with h_c = |e| / (d_c/t_c + r)
  // (junction_links), so dh_c/dt_c = h_c^2 d_c / (|e| t_c^2), and member
  // a's flux term is the star's (star_flux_derivative).
  std::vector<std::vector<double>> t, slope;
  for (const Conduit& c : _conduits)
    t.push_back(conductance(c)), slope.push_back(conductance_slope(c));
  for (const FaultJunction& j : _junctions)
  {
    std::vector<double> h, dh, p_i;
    std::vector<std::int64_t> cells;
    const double r = junction_resistance(j);
    for (std::size_t i = 0; i < j.cells.size(); ++i)
    {
      const std::size_t f = j.faults[i];
      const auto k = static_cast<std::size_t>(j.cells[i]);
      h.push_back(j.measure / (j.distances[i] / t[f][k] + r));
      dh.push_back(h[i] * h[i] * j.distances[i] * slope[f][k] / (j.measure * t[f][k] * t[f][k]));
      cells.push_back(_conduits[f].offset + j.cells[i]);
      p_i.push_back(p[cells[i]]);
    }
    const std::vector<double> dN = star_flux_derivative(h, p_i);
    for (std::size_t a = 0; a < h.size(); ++a)
      for (std::size_t c = 0; c < h.size() and _rows.owns(cells[a]); ++c)
        check_jacobian(MatSetValue(D, _rows.row[cells[a]], _rows.row[cells[c]], dN[h.size() * a + c] * dh[c],
                                   ADD_VALUES),
                       "MatSetValue");
  }
}

std::vector<double> ConduitFaults::conducting_lag() const
{
  std::vector<double> lag;
  for (const Conduit& c : _conduits)
    for (std::size_t k = 0; k < c.aperture.size(); ++k)
      lag.push_back(c.conducting.empty() ? 0.0 : c.aperture[k] - c.conducting[k]);
  return _rows.entries(lag);
}

} // namespace biotcontact
