#include "coupling/anderson.h"

#include <algorithm>
#include <cmath>

namespace biotcontact
{

AndersonAcceleration::AndersonAcceleration(MPI_Comm comm, int depth, std::vector<std::int32_t> owned,
                                           std::vector<double> weights)
    : _comm(comm), _depth(depth), _owned(std::move(owned)), _weights(std::move(weights))
{
}

bool AndersonAcceleration::restart()
{
  _f.clear();
  _g.clear();
  _dF.clear();
  _dG.clear();
  _gram.clear();
  return ++_restarts <= anderson_restarts;
}

double AndersonAcceleration::dot(const State& a, const State& b) const
{
  double local = 0;
  for (std::size_t k = 0; k < a.size(); ++k)
  {
    const double w = _weights[k] * _weights[k];
    for (std::int32_t i = 0; i < _owned[k]; ++i)
      local += w * a[k][i] * b[k][i];
  }
  double global = 0;
  MPI_Allreduce(&local, &global, 1, MPI_DOUBLE, MPI_SUM, _comm);
  return global;
}

namespace
{
/// Solves the symmetric positive semi-definite system H c = r by Cholesky;
/// false if a pivot falls below 1e-12 of the largest diagonal entry (the
/// differences are nearly dependent).
bool cholesky_solve(std::vector<double> H, std::vector<double>& c, int m)
{
  double largest = 0;
  for (int i = 0; i < m; ++i)
    largest = std::max(largest, H[i * m + i]);
  for (int j = 0; j < m; ++j)
  {
    for (int k = 0; k < j; ++k)
      H[j * m + j] -= H[j * m + k] * H[j * m + k];
    if (!(H[j * m + j] > 1e-12 * largest))
      return false;
    H[j * m + j] = std::sqrt(H[j * m + j]);
    for (int i = j + 1; i < m; ++i)
    {
      for (int k = 0; k < j; ++k)
        H[i * m + j] -= H[i * m + k] * H[j * m + k];
      H[i * m + j] /= H[j * m + j];
    }
  }
  for (int i = 0; i < m; ++i) // L y = r
  {
    for (int k = 0; k < i; ++k)
      c[i] -= H[i * m + k] * c[k];
    c[i] /= H[i * m + i];
  }
  for (int i = m - 1; i >= 0; --i) // L^T c = y
  {
    for (int k = i + 1; k < m; ++k)
      c[i] -= H[k * m + i] * c[k];
    c[i] /= H[i * m + i];
  }
  return true;
}
} // namespace

void AndersonAcceleration::next(State& x, const State& g)
{
  State f = g;
  for (std::size_t k = 0; k < f.size(); ++k)
    for (std::size_t i = 0; i < f[k].size(); ++i)
      f[k][i] -= x[k][i];
  if (!_f.empty())
  {
    // The newest differences f - f_prev, g - g_prev, and their row of the
    // Gram matrix; the oldest beyond `depth` are dropped.
    State df = f, dg = g;
    for (std::size_t k = 0; k < f.size(); ++k)
      for (std::size_t i = 0; i < f[k].size(); ++i)
      {
        df[k][i] -= _f[k][i];
        dg[k][i] -= _g[k][i];
      }
    if (static_cast<int>(_dF.size()) == _depth)
    {
      _dF.pop_front();
      _dG.pop_front();
      _gram.pop_front();
      for (auto& row : _gram)
        row.pop_front();
    }
    _dF.push_back(std::move(df));
    _dG.push_back(std::move(dg));
    std::deque<double> row;
    for (const State& d : _dF)
      row.push_back(dot(d, _dF.back()));
    for (std::size_t i = 0; i + 1 < _dF.size(); ++i)
      _gram[i].push_back(row[i]);
    _gram.push_back(std::move(row));
  }
  _f = f;
  _g = g;

  // Least squares by the normal equations dF^T dF c = dF^T f (m is small);
  // when the differences are nearly dependent the oldest are dropped.
  const int available = static_cast<int>(_dF.size());
  std::vector<double> projections(available);
  for (int i = 0; i < available; ++i)
    projections[i] = dot(_dF[i], f);
  std::vector<double> c;
  int m = available;
  for (; m > 0; --m)
  {
    const int first = available - m;
    std::vector<double> H(m * m);
    c.assign(projections.begin() + first, projections.end());
    for (int i = 0; i < m; ++i)
      for (int j = 0; j < m; ++j)
        H[i * m + j] = _gram[first + i][first + j];
    if (cholesky_solve(H, c, m))
      break;
  }
  x = g;
  for (int i = 0; i < m; ++i)
  {
    const State& d = _dG[available - m + i];
    for (std::size_t k = 0; k < x.size(); ++k)
      for (std::size_t e = 0; e < x[k].size(); ++e)
        x[k][e] -= c[i] * d[k][e];
  }
}

} // namespace biotcontact
