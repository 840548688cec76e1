// Where the wells are (domain/wells.h).
#include "domain/wells.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <span>
#include <dolfinx/common/IndexMap.h>

namespace biotcontact
{
using namespace dolfinx;

namespace
{
/// The weight of a cell for a well: 1 if the point (2D) lies in the
/// triangle (boundary included), or the length of the vertical segment (3D)
/// inside the tetrahedron, from the barycentric coordinates along it.
double well_weight(const std::vector<std::array<double, 3>>& v, const WellSpec& w, int d)
{
  const double tolerance = 1e-10;
  const double px = w.position[0], py = w.position[1];
  if (d == 2)
  {
    const double det = (v[1][0] - v[0][0]) * (v[2][1] - v[0][1]) - (v[2][0] - v[0][0]) * (v[1][1] - v[0][1]);
    const double l1 = ((px - v[0][0]) * (v[2][1] - v[0][1]) - (v[2][0] - v[0][0]) * (py - v[0][1])) / det;
    const double l2 = ((v[1][0] - v[0][0]) * (py - v[0][1]) - (px - v[0][0]) * (v[1][1] - v[0][1])) / det;
    return l1 >= -tolerance and l2 >= -tolerance and 1 - l1 - l2 >= -tolerance ? 1.0 : 0.0;
  }
  // lambda_i(s) = a_i + b_i s for the point (px, py, s), i = 1..3, from the
  // inverse of T = [v1 - v0, v2 - v0, v3 - v0]; lambda_0 = 1 - sum.
  std::array<std::array<double, 3>, 3> T, inverse;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      T[i][j] = v[j + 1][i] - v[0][i];
  const double det = T[0][0] * (T[1][1] * T[2][2] - T[1][2] * T[2][1])
                     - T[0][1] * (T[1][0] * T[2][2] - T[1][2] * T[2][0])
                     + T[0][2] * (T[1][0] * T[2][1] - T[1][1] * T[2][0]);
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
    {
      const int i1 = (j + 1) % 3, i2 = (j + 2) % 3, j1 = (i + 1) % 3, j2 = (i + 2) % 3;
      inverse[i][j] = (T[i1][j1] * T[i2][j2] - T[i1][j2] * T[i2][j1]) / det;
    }
  std::array<double, 4> a{1, 0, 0, 0}, b{0, 0, 0, 0};
  const std::array<double, 3> p0{px - v[0][0], py - v[0][1], -v[0][2]};
  for (int i = 0; i < 3; ++i)
  {
    a[i + 1] = inverse[i][0] * p0[0] + inverse[i][1] * p0[1] + inverse[i][2] * p0[2];
    b[i + 1] = inverse[i][2];
    a[0] -= a[i + 1];
    b[0] -= b[i + 1];
  }
  double low = w.bottom, high = w.top;
  for (int i = 0; i < 4; ++i)
  {
    if (std::abs(b[i]) < 1e-14 * (1 + std::abs(a[i])))
    {
      if (a[i] < -tolerance)
        return 0.0;
    }
    else if (b[i] > 0)
      low = std::max(low, -(a[i] + tolerance) / b[i]);
    else
      high = std::min(high, -(a[i] + tolerance) / b[i]);
  }
  return std::max(0.0, high - low);
}
} // namespace

std::string well_place(const WellSpec& w, int d)
{
  std::ostringstream s;
  s << "(" << w.position[0] << ", " << w.position[1] << ")";
  if (d == 3)
    s << " from z = " << w.bottom << " to " << w.top;
  return s.str();
}

WellCells locate_well(const Domain& domain, const WellSpec& w, const std::string& key)
{
  const mesh::Mesh& mesh = *domain.mesh;
  const int d = mesh.topology().dim();
  const auto& nodes = mesh.geometry().dofmap();
  std::span<const double> x = mesh.geometry().x();
  WellCells result;
  double total = 0;
  for (std::int32_t c = 0; c < mesh.topology().index_map(d)->size_local(); ++c)
  {
    std::vector<std::array<double, 3>> v;
    for (std::int32_t node : nodes.links(c))
      v.push_back({x[3 * node], x[3 * node + 1], x[3 * node + 2]});
    if (const double weight = well_weight(v, w, d); weight > 0)
    {
      result.cells.push_back(c);
      result.shares.push_back(weight);
      total += weight;
    }
  }
  MPI_Allreduce(MPI_IN_PLACE, &total, 1, MPI_DOUBLE, MPI_SUM, mesh.comm());
  const double length = d == 2 ? 1.0 : w.top - w.bottom;
  if (!(total >= length * (1 - 1e-9)))
  {
    throw SceneError(key + ": the well at " + well_place(w, d)
                     + (d == 2 or total == 0 ? " is not in the mesh" : " leaves the mesh"));
  }
  for (double& share : result.shares)
    share /= total;
  return result;
}

} // namespace biotcontact
