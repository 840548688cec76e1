// Unit tests of the split along faults (cpp/domain/faults.h), on the same
// handmade meshes with the same expected arrays as the prototype's twin
// tests/unit/test_faults.py: tips kept shared; a fault from the outer
// boundary splits its node there; a fault across the body cuts it in two;
// in 3D a patch keeps its rim; bad faults refused in one line naming the
// key; faults that cross (X) or end on one another (T) give their meeting
// node one node per piece around it, and their cells one junction there.
// Then gmsh meshes with an embedded curve: area kept, the two faces at the
// same points, each a face of one cell. Last, the cells of a fault's own
// flow (domain/fault_cells.h) on the fault across the square: cells, links
// and ends; the cells a well meets; the two-point transmissibility; BDF2's
// history value of the fault's storage.
#include "assembly/fault_flow.h"
#include "assembly/fault_flow_jacobian.h"
#include "domain/fault_cells.h"
#include "domain/faults.h"
#include "domain/gmsh_api.h"
#include "scene/input.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <gtest/gtest.h>
#include <map>
#include <set>
#include <unistd.h>

using namespace biotcontact;

namespace
{
const std::string prefix = "scene.toml: fault.";
constexpr int N = 4; // the 2D square [0, 4]^2: 4 x 4 squares, 32 triangles, node (i, j) = i + 5 j

using Facets = std::vector<std::vector<std::int64_t>>;
using Groups = std::vector<std::pair<std::string, Facets>>;

std::int64_t node(int i, int j, int k = 0)
{
  return i + (N + 1) * j + (N + 1) * (N + 1) * k;
}

InputMesh input_mesh(int d, std::vector<double> x, std::vector<std::int64_t> cells, const Groups& groups)
{
  InputMesh mesh{d, std::move(x), std::move(cells), {}, {}, {}};
  for (const auto& [name, facets] : groups)
  {
    for (const std::vector<std::int64_t>& facet : facets)
    {
      mesh.facets.insert(mesh.facets.end(), facet.begin(), facet.end());
      mesh.facet_group.push_back(static_cast<std::int32_t>(mesh.names.size()));
    }
    mesh.names.push_back(name);
  }
  return mesh;
}

/// The square's 4 x 4 unit squares, each cut along its diagonal from (i, j)
/// to (i+1, j+1); groups bottom, right, top, left, then `faults`.
InputMesh square(const Groups& faults)
{
  std::vector<double> x;
  for (int j = 0; j <= N; ++j)
    for (int i = 0; i <= N; ++i)
      x.insert(x.end(), {double(i), double(j)});
  std::vector<std::int64_t> cells;
  for (int j = 0; j < N; ++j)
    for (int i = 0; i < N; ++i)
    {
      const std::int64_t v = node(i, j);
      cells.insert(cells.end(), {v, v + node(1, 0), v + node(1, 1), v, v + node(1, 1), v + node(0, 1)});
    }
  Groups groups{{"bottom", {}}, {"right", {}}, {"top", {}}, {"left", {}}};
  for (int k = 0; k < N; ++k)
  {
    groups[0].second.push_back({node(k, 0), node(k + 1, 0)});
    groups[1].second.push_back({node(N, k), node(N, k + 1)});
    groups[2].second.push_back({node(k, N), node(k + 1, N)});
    groups[3].second.push_back({node(0, k), node(0, k + 1)});
  }
  groups.insert(groups.end(), faults.begin(), faults.end());
  return input_mesh(2, x, cells, groups);
}

/// The box [0, 4]^3: 4 x 4 x 4 unit cubes, each cut into 6 tetrahedra along
/// its diagonal (one per order of the axes, a conforming mesh); no groups
/// but `faults`.
InputMesh box(const Groups& faults)
{
  std::vector<double> x;
  for (int k = 0; k <= N; ++k)
    for (int j = 0; j <= N; ++j)
      for (int i = 0; i <= N; ++i)
        x.insert(x.end(), {double(i), double(j), double(k)});
  const std::array<std::int64_t, 3> step{node(1, 0), node(0, 1), node(0, 0, 1)};
  const std::array<std::array<int, 3>, 6> orders{{{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}}};
  std::vector<std::int64_t> cells;
  for (int k = 0; k < N; ++k)
    for (int j = 0; j < N; ++j)
      for (int i = 0; i < N; ++i)
        for (const std::array<int, 3>& order : orders)
        {
          cells.push_back(node(i, j, k));
          for (int axis : order)
            cells.push_back(cells.back() + step[axis]);
        }
  return input_mesh(3, x, cells, faults);
}

/// The triangles of the plane z = 2 over [lo, hi]^2, two per square, as the
/// box's tetrahedra have them.
Facets patch(int lo, int hi)
{
  Facets facets;
  for (int j = lo; j < hi; ++j)
    for (int i = lo; i < hi; ++i)
    {
      const std::int64_t v = node(i, j, 2);
      facets.push_back({v, v + node(1, 0), v + node(1, 1)});
      facets.push_back({v, v + node(0, 1), v + node(1, 1)});
    }
  return facets;
}

/// The triangles of the plane x = 2 over [lo, hi]^2 in (y, z), two per
/// square, as the box's tetrahedra have them.
Facets wall(int lo, int hi)
{
  Facets facets;
  for (int k = lo; k < hi; ++k)
    for (int j = lo; j < hi; ++j)
    {
      const std::int64_t v = node(2, j, k);
      facets.push_back({v, v + node(0, 1), v + node(0, 1, 1)});
      facets.push_back({v, v + node(0, 0, 1), v + node(0, 1, 1)});
    }
  return facets;
}

/// The facets of a polyline through the square's nodes (i, j).
Facets segment(const std::vector<std::pair<int, int>>& points)
{
  Facets facets;
  for (std::size_t k = 0; k + 1 < points.size(); ++k)
    facets.push_back({node(points[k].first, points[k].second), node(points[k + 1].first, points[k + 1].second)});
  return facets;
}

Facets joined(Facets a, const Facets& b)
{
  a.insert(a.end(), b.begin(), b.end());
  return a;
}

/// The cells that have all of `nodes`.
std::vector<std::int64_t> cells_with(const InputMesh& mesh, const std::vector<std::int64_t>& nodes)
{
  const int n = mesh.dim + 1;
  std::vector<std::int64_t> found;
  for (std::size_t c = 0; c < mesh.cells.size() / n; ++c)
  {
    const auto first = mesh.cells.begin() + c * n;
    const auto has = [&](std::int64_t v) { return std::find(first, first + n, v) != first + n; };
    if (std::all_of(nodes.begin(), nodes.end(), has))
      found.push_back(static_cast<std::int64_t>(c));
  }
  return found;
}

/// Row k of a flat array of `width` values per row.
std::vector<std::int64_t> row(const std::vector<std::int64_t>& values, std::size_t k, int width)
{
  return {values.begin() + k * width, values.begin() + (k + 1) * width};
}

/// The number of pieces of the mesh: cells joined through shared facets (a
/// union-find).
int pieces(const InputMesh& mesh)
{
  const int n = mesh.dim + 1;
  std::vector<std::size_t> parent(mesh.cells.size() / n);
  for (std::size_t c = 0; c < parent.size(); ++c)
    parent[c] = c;
  auto root = [&](std::size_t c)
  {
    while (parent[c] != c)
      c = parent[c] = parent[parent[c]];
    return c;
  };
  std::map<std::vector<std::int64_t>, std::size_t> first;
  for (std::size_t c = 0; c < parent.size(); ++c)
    for (int j = 0; j < n; ++j)
    {
      std::vector<std::int64_t> key;
      for (int i = 0; i < n; ++i)
        if (i != j)
          key.push_back(mesh.cells[c * n + i]);
      std::sort(key.begin(), key.end());
      if (const auto it = first.find(key); it != first.end())
        parent[root(c)] = root(it->second);
      first.emplace(key, c);
    }
  std::set<std::size_t> roots;
  for (std::size_t c = 0; c < parent.size(); ++c)
    roots.insert(root(c));
  return static_cast<int>(roots.size());
}

/// Node v's coordinates, z = 0 in 2D.
std::array<double, 3> point(const InputMesh& mesh, std::int64_t v)
{
  std::array<double, 3> p{0, 0, 0};
  for (int i = 0; i < mesh.dim; ++i)
    p[i] = mesh.x[v * mesh.dim + i];
  return p;
}

/// The total area (2D) or volume (3D) of the cells.
double volume(const InputMesh& mesh)
{
  const int n = mesh.dim + 1;
  double total = 0;
  for (std::size_t c = 0; c < mesh.cells.size() / n; ++c)
  {
    const std::array<double, 3> o = point(mesh, mesh.cells[c * n]);
    std::array<std::array<double, 3>, 3> e{{{0, 0, 0}, {0, 0, 0}, {0, 0, 1}}};
    for (int k = 1; k < n; ++k)
      for (int i = 0; i < 3; ++i)
        e[k - 1][i] = point(mesh, mesh.cells[c * n + k])[i] - o[i];
    const double det = e[0][0] * (e[1][1] * e[2][2] - e[1][2] * e[2][1])
                       - e[0][1] * (e[1][0] * e[2][2] - e[1][2] * e[2][0])
                       + e[0][2] * (e[1][0] * e[2][1] - e[1][1] * e[2][0]);
    total += std::abs(det) / (mesh.dim == 2 ? 2 : 6);
  }
  return total;
}

/// Each pair at one point; each facet's two faces at the same points and,
/// unless all its nodes are tips (then it stays shared: the same nodes, two
/// cells), each a face of one cell, the + face's cell on the side the normal
/// points into, the - face's on the other; every facet left in the groups
/// (all on the outer boundary here) a face of one cell.
void check_split(const InputMesh& mesh, const SplitFault& fault)
{
  const int d = mesh.dim;
  for (const auto& [plus, minus] : fault.pairs)
    EXPECT_EQ(point(mesh, plus), point(mesh, minus));
  for (std::size_t k = 0; k < fault.normals.size(); ++k)
  {
    const std::vector<std::int64_t> plus = row(fault.plus_facets, k, d), minus = row(fault.minus_facets, k, d);
    const std::array<double, 3>& n = fault.normals[k];
    for (int i = 0; i < d; ++i)
      EXPECT_EQ(point(mesh, plus[i]), point(mesh, minus[i]));
    EXPECT_NEAR(std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]), 1.0, 1e-15);
    if (std::all_of(plus.begin(), plus.end(), [&](std::int64_t v)
                    { return std::binary_search(fault.tips.begin(), fault.tips.end(), v); }))
    {
      EXPECT_EQ(plus, minus);
      EXPECT_EQ(cells_with(mesh, plus).size(), 2u) << "facet " << k;
      continue;
    }
    for (const auto& [face, sign] : {std::pair{plus, 1.0}, std::pair{minus, -1.0}})
    {
      const std::vector<std::int64_t> cells = cells_with(mesh, face);
      ASSERT_EQ(cells.size(), 1u) << "facet " << k << (sign > 0 ? " +" : " -");
      double along = 0;
      for (int i = 0; i < d; ++i)
      {
        double centroid = 0;
        for (int j = 0; j <= d; ++j)
          centroid += point(mesh, mesh.cells[cells[0] * (d + 1) + j])[i] / (d + 1);
        along += (centroid - point(mesh, face[0])[i]) * n[i];
      }
      EXPECT_GT(sign * along, 0) << "facet " << k;
    }
  }
  for (std::size_t f = 0; f < mesh.facet_group.size(); ++f)
    EXPECT_EQ(cells_with(mesh, row(mesh.facets, f, d)).size(), 1u) << "facet " << f;
}

std::vector<SplitFault> split(InputMesh& mesh, const std::vector<FaultRequest>& faults)
{
  return split_along_faults(mesh, faults, prefix);
}

/// The pairs as flat (plus, minus) values.
std::vector<std::int64_t> flat(const std::vector<std::pair<std::int64_t, std::int64_t>>& pairs)
{
  std::vector<std::int64_t> values;
  for (const auto& [plus, minus] : pairs)
    values.insert(values.end(), {plus, minus});
  return values;
}
} // namespace

TEST(Faults, InteriorSegmentKeepsItsTips)
{
  // From (1, 2) to (3, 2): (2, 2) = node 12 doubled, its ends shared.
  InputMesh mesh = square({{"fault", segment({{1, 2}, {2, 2}, {3, 2}})}});
  const std::vector<std::int64_t> boundary(mesh.facets.begin(), mesh.facets.begin() + 32);
  const std::vector<SplitFault> faults = split(mesh, {{"fault", {0, 1, 0}}});
  ASSERT_EQ(faults.size(), 1u);
  const SplitFault& fault = faults[0];
  EXPECT_EQ(fault.name, "fault");
  EXPECT_EQ(mesh.cells.size(), 32u * 3);
  EXPECT_EQ(mesh.x.size(), 26u * 2);
  EXPECT_EQ(flat(fault.pairs), (std::vector<std::int64_t>{25, 12}));
  EXPECT_EQ(fault.tips, (std::vector<std::int64_t>{11, 13}));
  EXPECT_EQ(fault.plus_facets, (std::vector<std::int64_t>{11, 25, 25, 13}));
  EXPECT_EQ(fault.minus_facets, (std::vector<std::int64_t>{11, 12, 12, 13}));
  EXPECT_EQ(fault.normals, (std::vector<std::array<double, 3>>{{0, 1, 0}, {0, 1, 0}}));
  // The + side's cells around (2, 2) took the new node, the others kept it.
  EXPECT_EQ(cells_with(mesh, {25}), (std::vector<std::int64_t>{18, 20, 21}));
  EXPECT_EQ(cells_with(mesh, {12}), (std::vector<std::int64_t>{10, 11, 13}));
  // The fault's facets left the groups; the boundary's are unchanged.
  EXPECT_EQ(mesh.facets, boundary);
  EXPECT_EQ(mesh.facet_group, (std::vector<std::int32_t>{0, 0, 0, 0, 1, 1, 1, 1, 2, 2, 2, 2, 3, 3, 3, 3}));
  EXPECT_EQ(mesh.names, (std::vector<std::string>{"bottom", "right", "top", "left", "fault"}));
  EXPECT_EQ(pieces(mesh), 1);
  check_split(mesh, fault);
}

TEST(Faults, SegmentFromTheBoundarySplitsIt)
{
  // From (0, 2) on the left edge to (2, 2): nodes 10 and 11 doubled, the
  // left edge's facet above (0, 2) renumbered to the + side's node.
  InputMesh mesh = square({{"fault", segment({{0, 2}, {1, 2}, {2, 2}})}});
  std::vector<std::int64_t> boundary(mesh.facets.begin(), mesh.facets.begin() + 32);
  const SplitFault fault = split(mesh, {{"fault", {0, 1, 0}}}).at(0);
  EXPECT_EQ(mesh.x.size(), 27u * 2);
  EXPECT_EQ(flat(fault.pairs), (std::vector<std::int64_t>{25, 10, 26, 11}));
  EXPECT_EQ(fault.tips, (std::vector<std::int64_t>{12}));
  EXPECT_EQ(fault.plus_facets, (std::vector<std::int64_t>{25, 26, 26, 12}));
  EXPECT_EQ(fault.minus_facets, (std::vector<std::int64_t>{10, 11, 11, 12}));
  boundary[2 * 14] = 25;
  EXPECT_EQ(mesh.facets, boundary);
  EXPECT_EQ(pieces(mesh), 1);
  check_split(mesh, fault);
}

TEST(Faults, SegmentAcrossCutsTheBodyInTwo)
{
  InputMesh mesh = square({{"fault", segment({{0, 2}, {1, 2}, {2, 2}, {3, 2}, {4, 2}})}});
  std::vector<std::int64_t> boundary(mesh.facets.begin(), mesh.facets.begin() + 32);
  const SplitFault fault = split(mesh, {{"fault", {0, -2, 0}}}).at(0);
  // The hint points down: the lower half is the + side.
  EXPECT_EQ(flat(fault.pairs), (std::vector<std::int64_t>{25, 10, 26, 11, 27, 12, 28, 13, 29, 14}));
  EXPECT_TRUE(fault.tips.empty());
  for (const std::array<double, 3>& n : fault.normals)
    EXPECT_EQ(n[1], -1);
  boundary[2 * 5 + 1] = 29;
  boundary[2 * 13 + 1] = 25;
  EXPECT_EQ(mesh.facets, boundary);
  EXPECT_EQ(pieces(mesh), 2);
  const std::set<std::int64_t> lower(mesh.cells.begin(), mesh.cells.begin() + 16 * 3),
      upper(mesh.cells.begin() + 16 * 3, mesh.cells.end());
  for (std::int64_t v : lower)
    EXPECT_EQ(upper.count(v), 0u) << "node " << v;
  check_split(mesh, fault);
}

TEST(Faults, InteriorPatchIn3dKeepsItsRim)
{
  // The square [1, 3]^2 of the plane z = 2: (2, 2, 2) = node 62 doubled, the
  // 8 rim nodes shared; the 2 triangles with every node on the rim (57 58 63
  // and 61 66 67) stay shared.
  InputMesh mesh = box({{"patch", patch(1, 3)}});
  const SplitFault fault = split(mesh, {{"patch", {0, 0, 1}}}).at(0);
  EXPECT_EQ(mesh.cells.size(), 384u * 4);
  EXPECT_EQ(mesh.x.size(), 126u * 3);
  EXPECT_EQ(flat(fault.pairs), (std::vector<std::int64_t>{125, 62}));
  EXPECT_EQ(fault.tips, (std::vector<std::int64_t>{56, 57, 58, 61, 63, 66, 67, 68}));
  std::vector<std::int64_t> minus, plus;
  for (const std::vector<std::int64_t>& facet : patch(1, 3))
    for (std::int64_t v : facet)
    {
      minus.push_back(v);
      plus.push_back(v == 62 ? 125 : v);
    }
  EXPECT_EQ(fault.minus_facets, minus);
  EXPECT_EQ(fault.plus_facets, plus);
  EXPECT_EQ(fault.normals, (std::vector<std::array<double, 3>>(8, {0, 0, 1})));
  EXPECT_TRUE(mesh.facets.empty());
  EXPECT_EQ(pieces(mesh), 1);
  check_split(mesh, fault);
}

TEST(Faults, PlaneAcrossTheBoxCutsItInTwo)
{
  InputMesh mesh = box({{"plane", patch(0, 4)}});
  const SplitFault fault = split(mesh, {{"plane", {0, 0, 1}}}).at(0);
  std::vector<std::int64_t> pairs;
  for (std::int64_t v = 0; v < 25; ++v)
    pairs.insert(pairs.end(), {125 + v, 50 + v});
  EXPECT_EQ(flat(fault.pairs), pairs);
  EXPECT_TRUE(fault.tips.empty());
  EXPECT_EQ(pieces(mesh), 2);
  check_split(mesh, fault);
}

namespace
{
/// The one-line message the split refuses with.
std::string refused(InputMesh mesh, const std::vector<FaultRequest>& faults)
{
  try
  {
    split(mesh, faults);
  }
  catch (const SceneError& e)
  {
    const std::string message = e.what();
    EXPECT_EQ(message.find('\n'), std::string::npos) << message;
    return message;
  }
  ADD_FAILURE() << "not refused";
  return "";
}
} // namespace

TEST(FaultRefusals, AGroupOnTheOuterBoundary)
{
  EXPECT_EQ(refused(square({}), {{"left", {1, 0, 0}}}),
            "scene.toml: fault.left: the group left lies on the outer boundary at (0, 0.5) "
            "(a fault is inside the body)");
}

TEST(FaultRefusals, AMissingOrEmptyGroup)
{
  EXPECT_EQ(refused(square({{"empty", {}}}), {{"empty", {0, 1, 0}}}),
            "scene.toml: fault.empty: the group empty has no facets");
  EXPECT_EQ(refused(square({}), {{"main", {0, 1, 0}}}),
            "scene.toml: fault.main: the mesh has no group main (its facet groups: bottom, right, top, left)");
}

TEST(FaultRefusals, ABranchingFault)
{
  const InputMesh mesh = square({{"t", joined(segment({{1, 2}, {2, 2}, {3, 2}}), segment({{2, 2}, {2, 3}}))}});
  EXPECT_EQ(refused(mesh, {{"t", {1, 1, 0}}}),
            "scene.toml: fault.t: the fault branches or crosses itself at (2, 2) (3 pieces meet there): give "
            "each branch a fault (a physical group) of its own");
}

// Faults that cross (X) or end on one another (T) in the square: the node
// where they meet, (2, 2) = 12, gets one node per piece around it, 12 kept
// by the piece below the first fault's first facet, the others new (25, 26,
// 27) in the order of their first cells; each fault pairs, facet by facet,
// the nodes of its + and - pieces.
TEST(FaultIntersections, CrossingFaults)
{
  InputMesh mesh = square({{"h", segment({{1, 2}, {2, 2}, {3, 2}})}, {"v", segment({{2, 1}, {2, 2}, {2, 3}})}});
  const std::vector<SplitFault> faults = split(mesh, {{"h", {0, 1, 0}}, {"v", {1, 0, 0}}});
  ASSERT_EQ(faults.size(), 2u);
  const SplitFault &h = faults[0], &v = faults[1];
  EXPECT_EQ(mesh.x.size(), 28u * 2);
  EXPECT_EQ(std::vector<double>(mesh.x.begin() + 50, mesh.x.end()), (std::vector<double>{2, 2, 2, 2, 2, 2}));
  // pieces SW (cells 10, 11: keeps 12), SE (13: 25), NW (18: 26), NE (20, 21: 27)
  EXPECT_EQ(cells_with(mesh, {12}), (std::vector<std::int64_t>{10, 11}));
  EXPECT_EQ(cells_with(mesh, {25}), (std::vector<std::int64_t>{13}));
  EXPECT_EQ(cells_with(mesh, {26}), (std::vector<std::int64_t>{18}));
  EXPECT_EQ(cells_with(mesh, {27}), (std::vector<std::int64_t>{20, 21}));
  EXPECT_EQ(flat(h.pairs), (std::vector<std::int64_t>{26, 12, 27, 25}));
  EXPECT_EQ(flat(v.pairs), (std::vector<std::int64_t>{25, 12, 27, 26}));
  EXPECT_EQ(h.tips, (std::vector<std::int64_t>{11, 13}));
  EXPECT_EQ(v.tips, (std::vector<std::int64_t>{7, 17}));
  using Meets = std::vector<std::pair<std::int64_t, std::size_t>>;
  EXPECT_EQ(h.meets, (Meets{{12, 1}}));
  EXPECT_EQ(v.meets, (Meets{{12, 0}}));
  EXPECT_EQ(pieces(mesh), 1); // the tips hold the pieces together
}

TEST(FaultIntersections, AFaultEndingOnAnother)
{
  InputMesh mesh = square({{"h", segment({{1, 2}, {2, 2}, {3, 2}})}, {"s", segment({{2, 2}, {2, 3}})}});
  const std::vector<SplitFault> faults = split(mesh, {{"h", {0, 1, 0}}, {"s", {1, 0, 0}}});
  ASSERT_EQ(faults.size(), 2u);
  const SplitFault &h = faults[0], &t = faults[1];
  EXPECT_EQ(mesh.x.size(), 27u * 2);
  // pieces below h (cells 10, 11, 13: keeps 12), NW (18: 25), NE (20, 21: 26)
  EXPECT_EQ(cells_with(mesh, {12}), (std::vector<std::int64_t>{10, 11, 13}));
  EXPECT_EQ(cells_with(mesh, {25}), (std::vector<std::int64_t>{18}));
  EXPECT_EQ(cells_with(mesh, {26}), (std::vector<std::int64_t>{20, 21}));
  EXPECT_EQ(flat(h.pairs), (std::vector<std::int64_t>{25, 12, 26, 12}));
  EXPECT_EQ(flat(t.pairs), (std::vector<std::int64_t>{26, 25}));
  EXPECT_EQ(t.tips, (std::vector<std::int64_t>{17}));
  using Meets = std::vector<std::pair<std::int64_t, std::size_t>>;
  EXPECT_EQ(h.meets, (Meets{{12, 1}}));
  EXPECT_EQ(t.meets, (Meets{{12, 0}}));
}

// The network of the faults' cells (domain/fault_cells.h, fault_network):
// where faults meet, the cells with an edge there are one junction's
// members, and a link of one fault there joins the junction.
// In 3D a fault's rim may cross another fault: the wall x = 2 over
// [1, 3]^2 in (y, z) crosses the plane z = 2 that cuts the box, and its rim
// edges y = 1 and y = 3 cross the plane at (2, 1, 2) and (2, 3, 2). There
// the wall's sides stay joined on each side of the plane (two copies, the
// plane's); the wall's centre (2, 2, 2) gets one copy per sector (4).
TEST(FaultIntersections, ARimCrossingAnotherFault)
{
  InputMesh mesh = box({{"plane", patch(0, 4)}, {"wall", wall(1, 3)}});
  const std::vector<SplitFault> faults = split(mesh, {{"plane", {0, 0, 1}}, {"wall", {1, 0, 0}}});
  ASSERT_EQ(faults.size(), 2u);
  EXPECT_EQ(mesh.x.size(), (125u + 25u + 2u) * 3);
  EXPECT_EQ(pieces(mesh), 2);
  EXPECT_NEAR(volume(mesh), 64.0, 1e-12);
  const SplitFault& w = faults[1];
  EXPECT_EQ(w.pairs.size(), 2u); // (2, 2, 2) above and below the plane
  EXPECT_EQ(w.tips.size(), 8u + 2u); // the rim, and the plane's copies where it crosses
  EXPECT_TRUE(std::is_sorted(w.tips.begin(), w.tips.end()));
  std::set<std::array<double, 3>> rim;
  for (std::int64_t v : w.tips)
    rim.insert(point(mesh, v));
  EXPECT_EQ(rim, (std::set<std::array<double, 3>>{
                     {2, 1, 1}, {2, 2, 1}, {2, 3, 1}, {2, 1, 2}, {2, 3, 2}, {2, 1, 3}, {2, 2, 3}, {2, 3, 3}}));
  for (const SplitFault& f : faults)
    check_split(mesh, f);
  // Each is cut along the other over y in [1, 3]: two edges, two cut links.
  EXPECT_EQ(fault_cells(mesh, faults[0]).cut.size(), 2u);
  EXPECT_EQ(fault_cells(mesh, faults[1]).cut.size(), 2u);
}

TEST(FaultNetwork, CrossingFaultsMeetAtOneJunctionOfFourCells)
{
  InputMesh mesh = square({{"h", segment({{1, 2}, {2, 2}, {3, 2}})}, {"v", segment({{2, 1}, {2, 2}, {2, 3}})}});
  const std::vector<SplitFault> faults = split(mesh, {{"h", {0, 1, 0}}, {"v", {1, 0, 0}}});
  const FaultCells h = fault_cells(mesh, faults[0]), v = fault_cells(mesh, faults[1]);
  EXPECT_EQ(h.links.size() + v.links.size(), 0u); // the crossing separates each fault's two cells
  EXPECT_EQ(h.inner.size(), 4u);                  // two tips, two edges at the crossing
  // ... and the two edges at the crossing are one cut link of its plane
  for (const FaultCells* f : {&h, &v})
  {
    EXPECT_EQ(f->cut.cells, (std::vector<std::int64_t>{0, 1}));
    EXPECT_EQ(f->cut.points, (std::vector<std::array<double, 3>>{{2, 2, 0}}));
  }
  const FaultNetwork network = fault_network({&h, &v});
  ASSERT_EQ(network.junctions.size(), 1u); // the tips meet nothing
  const FaultJunction& j = network.junctions[0];
  EXPECT_EQ(j.point, (std::array<double, 3>{2, 2, 0}));
  EXPECT_EQ(j.measure, 1.0);
  EXPECT_EQ(j.faults, (std::vector<std::size_t>{0, 0, 1, 1}));
  EXPECT_EQ(j.cells, (std::vector<std::int64_t>{0, 1, 0, 1}));
  EXPECT_EQ(j.distances, std::vector<double>(4, 0.5));
}

TEST(FaultNetwork, ALinkAtAJunctionJoinsIt)
{
  // A T: s ends on h from above. With h's + side above, the stem separates
  // h's cells (two inner edges at (2, 2)); with it below they keep their
  // link there, which leaves h's links for the junction.
  for (double side : {1.0, -1.0})
  {
    InputMesh mesh = square({{"h", segment({{1, 2}, {2, 2}, {3, 2}})}, {"s", segment({{2, 2}, {2, 3}})}});
    const std::vector<SplitFault> faults = split(mesh, {{"h", {0, side, 0}}, {"s", {1, 0, 0}}});
    const FaultCells h = fault_cells(mesh, faults[0]), s = fault_cells(mesh, faults[1]);
    EXPECT_EQ(h.links.size(), side > 0 ? 0u : 1u);
    EXPECT_EQ(h.cut.size(), side > 0 ? 1u : 0u); // the separated link, cut; the stem's end is a tip
    EXPECT_EQ(s.cut.size(), 0u);
    const FaultNetwork network = fault_network({&h, &s});
    EXPECT_EQ(network.links[0].size() + network.links[1].size(), 0u);
    ASSERT_EQ(network.junctions.size(), 1u);
    EXPECT_EQ(network.junctions[0].faults, (std::vector<std::size_t>{0, 0, 1}));
    EXPECT_EQ(network.junctions[0].cells, (std::vector<std::int64_t>{0, 1, 0}));
    // h alone (s no conduit) keeps its link, or its two cells meet at a
    // junction of two where s separates them: one conduit through s
    const FaultNetwork alone = fault_network({&h});
    EXPECT_EQ(alone.links[0].cells, h.links.cells);
    EXPECT_EQ(alone.junctions.size(), side > 0 ? 1u : 0u);
  }
}

TEST(FaultRefusals, AHintParallelToTheFault)
{
  const InputMesh mesh = square({{"h", segment({{1, 2}, {2, 2}, {3, 2}})}});
  EXPECT_EQ(refused(mesh, {{"h", {1, 0, 0}}}),
            "scene.toml: fault.h.normal: the hint is parallel to the fault at (1.5, 2): give a normal that "
            "crosses it");
}

TEST(FaultRefusals, AHintThatOrientsATurningFaultBothWays)
{
  // An L: left of (2, 2) along y, then up along x. The hint (1, 1) puts the
  // + side above the first leg and right of the second: the + and - sides
  // swap at the corner. (1, -1) puts both on the outside.
  InputMesh mesh = square({{"l", segment({{1, 2}, {2, 2}, {2, 3}})}});
  EXPECT_EQ(refused(mesh, {{"l", {1, 1, 0}}}),
            "scene.toml: fault.l: the normal hint orients the fault inconsistently at (2, 2) (the fault turns "
            "past the hint there: give a hint that crosses all of it the same way)");
  const SplitFault fault = split(mesh, {{"l", {1, -1, 0}}}).at(0);
  EXPECT_EQ(flat(fault.pairs), (std::vector<std::int64_t>{25, 12}));
  EXPECT_EQ(fault.tips, (std::vector<std::int64_t>{11, 17}));
}

namespace
{
// The rectangle [0, 4] x [0, 2] with a segment embedded: inside, from (1,
// 0.8) to (3, 1.3); across, from (0, 0.8) to (4, 1.3), whose ends are points
// of the outline (so that the outline's mesh has them).
const char* inside = R"(
h = 0.25;
Point(1) = {0, 0, 0, h}; Point(2) = {4, 0, 0, h}; Point(3) = {4, 2, 0, h}; Point(4) = {0, 2, 0, h};
Point(5) = {1, 0.8, 0, h}; Point(6) = {3, 1.3, 0, h};
Line(1) = {1, 2}; Line(2) = {2, 3}; Line(3) = {3, 4}; Line(4) = {4, 1}; Line(5) = {5, 6};
Curve Loop(1) = {1, 2, 3, 4}; Plane Surface(1) = {1};
Curve{5} In Surface{1};
Physical Curve("bottom") = {1}; Physical Curve("right") = {2}; Physical Curve("top") = {3};
Physical Curve("left") = {4}; Physical Curve("fault") = {5}; Physical Surface("rock") = {1};
)";
const char* across = R"(
h = 0.25;
Point(1) = {0, 0, 0, h}; Point(2) = {4, 0, 0, h}; Point(3) = {4, 2, 0, h}; Point(4) = {0, 2, 0, h};
Point(5) = {0, 0.8, 0, h}; Point(6) = {4, 1.3, 0, h};
Line(1) = {1, 2}; Line(2) = {2, 6}; Line(3) = {6, 3}; Line(4) = {3, 4}; Line(6) = {4, 5}; Line(7) = {5, 1};
Line(5) = {5, 6};
Curve Loop(1) = {1, 2, 3, 4, 6, 7}; Plane Surface(1) = {1};
Curve{5} In Surface{1};
Physical Curve("bottom") = {1}; Physical Curve("right") = {2, 3}; Physical Curve("top") = {4};
Physical Curve("left") = {6, 7}; Physical Curve("fault") = {5}; Physical Surface("rock") = {1};
)";

/// The mesh gmsh makes of `geo`, as the reader reads it (the nodes of the
/// cells only, in their order).
InputMesh gmsh_mesh(const char* geo)
{
  const std::filesystem::path file
      = std::filesystem::temp_directory_path() / ("test_faults_" + std::to_string(getpid()) + ".geo");
  std::ofstream(file) << geo;
  gmsh::initialize();
  gmsh::option::setNumber("General.Terminal", 0);
  gmsh::open(file.string());
  std::filesystem::remove(file);
  gmsh::model::mesh::generate(2);
  std::vector<std::size_t> tags, element_tags, node_tags;
  std::vector<double> coords;
  gmsh::model::mesh::getNodes(tags, coords);
  std::map<std::size_t, std::int64_t> index;
  for (std::size_t i = 0; i < tags.size(); ++i)
    index[tags[i]] = -1;
  gmsh::model::mesh::getElementsByType(2, element_tags, node_tags);
  for (std::size_t t : node_tags)
    index[t] = 0;
  // Number the nodes of the cells in their order in gmsh's list.
  std::vector<double> x;
  for (std::size_t i = 0, used = 0; i < tags.size(); ++i)
    if (index[tags[i]] == 0)
    {
      index[tags[i]] = static_cast<std::int64_t>(used++);
      x.insert(x.end(), {coords[3 * i], coords[3 * i + 1]});
    }
  std::vector<std::int64_t> cells;
  for (std::size_t t : node_tags)
    cells.push_back(index.at(t));
  Groups groups;
  gmsh::vectorpair physical;
  gmsh::model::getPhysicalGroups(physical, 1);
  for (const auto& [dim, tag] : physical)
  {
    std::string name;
    gmsh::model::getPhysicalName(dim, tag, name);
    std::vector<int> entities;
    gmsh::model::getEntitiesForPhysicalGroup(dim, tag, entities);
    Facets facets;
    for (int entity : entities)
    {
      std::vector<std::size_t> etags, ntags;
      gmsh::model::mesh::getElementsByType(1, etags, ntags, entity);
      for (std::size_t k = 0; k < ntags.size(); k += 2)
        facets.push_back({index.at(ntags[k]), index.at(ntags[k + 1])});
    }
    groups.emplace_back(name, facets);
  }
  gmsh::finalize();
  return input_mesh(2, x, cells, groups);
}

SplitFault split_gmsh(InputMesh& mesh)
{
  const double area = volume(mesh);
  const std::size_t cells = mesh.cells.size(), nodes = mesh.x.size() / 2;
  const SplitFault fault = split(mesh, {{"fault", {-0.2, 1, 0}}}).at(0);
  EXPECT_EQ(mesh.cells.size(), cells);
  EXPECT_NEAR(volume(mesh), area, 1e-12 * area);
  EXPECT_NEAR(area, 8.0, 1e-12);
  EXPECT_EQ(mesh.x.size() / 2, nodes + fault.pairs.size());
  check_split(mesh, fault);
  return fault;
}
} // namespace

TEST(FaultGmshMeshes, InteriorCurve)
{
  InputMesh mesh = gmsh_mesh(inside);
  const SplitFault fault = split_gmsh(mesh);
  ASSERT_EQ(fault.tips.size(), 2u);
  std::set<std::array<double, 3>> ends{point(mesh, fault.tips[0]), point(mesh, fault.tips[1])};
  EXPECT_EQ(ends, (std::set<std::array<double, 3>>{{1, 0.8, 0}, {3, 1.3, 0}}));
  EXPECT_EQ(fault.pairs.size(), fault.normals.size() - 1);
  EXPECT_EQ(pieces(mesh), 1);
}

TEST(FaultGmshMeshes, CurveAcross)
{
  InputMesh mesh = gmsh_mesh(across);
  const SplitFault fault = split_gmsh(mesh);
  EXPECT_TRUE(fault.tips.empty());
  EXPECT_EQ(fault.pairs.size(), fault.normals.size() + 1);
  EXPECT_EQ(pieces(mesh), 2);
}

TEST(FaultCells, CellsOfTheFaultAcross)
{
  InputMesh mesh = square({{"fault", segment({{0, 2}, {1, 2}, {2, 2}, {3, 2}, {4, 2}})}});
  const SplitFault fault = split(mesh, {{"fault", {0, -2, 0}}}).at(0);
  const FaultCells cells = fault_cells(mesh, fault);
  EXPECT_EQ(cells.keys, (std::vector<std::int64_t>{25, 26, 26, 27, 27, 28, 28, 29}));
  // Each key's twin is the input node it was doubled from, on the - face;
  // the normal points into the + side, along the hint.
  EXPECT_EQ(cells.twins, (std::vector<std::int64_t>{10, 11, 11, 12, 12, 13, 13, 14}));
  for (int i = 0; i < 4; ++i)
    EXPECT_EQ(cells.normals[i], (std::array<double, 3>{0.0, -1.0, 0.0}));
  EXPECT_EQ(cells.measures, std::vector<double>(4, 1.0));
  for (int i = 0; i < 4; ++i)
    EXPECT_EQ(cells.centroids[i], (std::array<double, 3>{i + 0.5, 2.0, 0.0}));
  EXPECT_EQ(cells.links.cells, (std::vector<std::int64_t>{0, 1, 1, 2, 2, 3}));
  EXPECT_EQ(cells.links.measures, std::vector<double>(3, 1.0));
  EXPECT_EQ(cells.links.distances, std::vector<double>(6, 0.5));
  EXPECT_EQ(cells.ends.cells, (std::vector<std::int64_t>{0, 3}));
  EXPECT_EQ(cells.end_groups, (std::vector<std::string>{"left", "right"}));
  EXPECT_EQ(cells.ends.distances, std::vector<double>(2, 0.5));
  EXPECT_EQ(cells.ends.points[0], (std::array<double, 3>{0.0, 2.0, 0.0}));
  EXPECT_EQ(cells.ends.points[1], (std::array<double, 3>{4.0, 2.0, 0.0}));
  auto well = [&](double x, double y)
  {
    WellSpec w;
    w.position = {x, y};
    return well_cells(cells, w);
  };
  EXPECT_EQ(well(2.0, 2.0).cells, (std::vector<std::int64_t>{1, 2}));
  EXPECT_EQ(well(2.0, 2.0).shares, (std::vector<double>{0.5, 0.5}));
  EXPECT_EQ(well(2.5, 2.0).cells, (std::vector<std::int64_t>{2}));
  EXPECT_EQ(well(2.5, 2.0).shares, (std::vector<double>{1.0}));
  EXPECT_TRUE(well(2.0, 3.0).cells.empty());
}

TEST(FaultCells, Transmissibility)
{
  FaultEdges edges(2);
  edges.cells = {0, 1};
  edges.measures = {2.0};
  edges.distances = {0.5, 1.5};
  edges.points = {{0, 0, 0}};
  // |e| / (d_0/t_0 + d_1/t_1) = 2 / (0.5/1 + 1.5/3)
  EXPECT_EQ(transmissibilities(std::vector<double>{1.0, 3.0}, edges), std::vector<double>{2.0});
}

TEST(FaultCells, TransmissibilitySlopes)
{
  // dT/dw of a link (width 2) and of an end (width 1) against central
  // differences of transmissibilities, with the cubic law's t = w^3.
  FaultEdges links(2), ends(1);
  links.cells = {0, 1}, links.measures = {2.0}, links.distances = {0.5, 1.5}, links.points = {{0, 0, 0}};
  ends.cells = {1}, ends.measures = {0.7}, ends.distances = {0.25}, ends.points = {{0, 0, 0}};
  auto cubed = [](std::vector<double> w)
  {
    for (double& x : w)
      x = x * x * x;
    return w;
  };
  const std::vector<double> w{1.3, 0.6}, slope{3 * 1.3 * 1.3, 3 * 0.6 * 0.6};
  for (const FaultEdges* edges : {&links, &ends})
  {
    const std::vector<double> dT = transmissibility_slopes(cubed(w), slope, *edges);
    for (int i = 0; i < edges->width; ++i)
    {
      std::vector<double> up = w, down = w;
      const double h = 1e-6;
      up[edges->cells[i]] += h, down[edges->cells[i]] -= h;
      const double fd = (transmissibilities(cubed(up), *edges)[0] - transmissibilities(cubed(down), *edges)[0]) / (2 * h);
      EXPECT_NEAR(dT[i], fd, 1e-7 * std::abs(fd));
    }
  }
}

TEST(FaultCells, JunctionStarDerivative)
{
  // dN_a/dh_c of three members against central differences of N_a = -h_a
  // (p_a - p_j); the fluxes into the junction sum to zero for every h, so
  // each column sums to zero.
  const std::vector<double> h{2.0, 0.5, 1.25}, p{3.0, -1.0, 0.5};
  auto N = [&p](const std::vector<double>& g, std::size_t a)
  {
    const double p_j = (g[0] * p[0] + g[1] * p[1] + g[2] * p[2]) / (g[0] + g[1] + g[2]);
    return -g[a] * (p[a] - p_j);
  };
  const std::vector<double> dN = star_flux_derivative(h, p);
  for (std::size_t c = 0; c < 3; ++c)
  {
    std::vector<double> up = h, down = h;
    up[c] += 1e-6, down[c] -= 1e-6;
    for (std::size_t a = 0; a < 3; ++a)
      EXPECT_NEAR(dN[3 * a + c], (N(up, a) - N(down, a)) / 2e-6, 1e-8);
    EXPECT_NEAR(dN[c] + dN[3 + c] + dN[6 + c], 0.0, 1e-14);
  }
}

TEST(FaultCells, HistoryValue)
{
  // y = t^2 at t = 0, 1, 3: the step dt = 2 after dt = 1 (w = 2) has
  // c = (5/3, 3, 4/3), dt/c0 = 1.2, and c0 (y - y*)/dt = y'(3) = 6 exactly
  // (BDF2 is exact for quadratics); backward Euler's y* is y_n itself.
  const FineStep bdf2{3.0, 1.2, 1, 1, {5.0 / 3, 3.0, 4.0 / 3}};
  const std::vector<double> y_n{1.0}, y_before{0.0};
  EXPECT_NEAR((9.0 - history_value(bdf2, y_n, y_before)[0]) / bdf2.dt, 6.0, 1e-14);
  EXPECT_EQ(history_value(FineStep{3.0, 2.0}, y_n, y_before), y_n);
}

TEST(FaultCells, OpenPatches)
{
  // A chain of 6 cells, 0-1-2-3-4-5, and a 7th linked to 0: open 0, 1, 3,
  // 4, 6 make the patches {0, 1, 6} and {3, 4}; 2 and 5 are closed.
  FaultEdges links(2);
  links.cells = {0, 1, 1, 2, 2, 3, 3, 4, 4, 5, 6, 0};
  links.measures.assign(6, 1.0);
  const std::vector<char> open{1, 1, 0, 1, 1, 0, 1};
  EXPECT_EQ(open_patches({&links}, open), (std::vector<std::int64_t>{0, 0, -1, 1, 1, -1, 0}));
  EXPECT_EQ(open_patches({&links}, std::vector<char>(7, 0)), std::vector<std::int64_t>(7, -1));
  // A link cut at another fault, 1-4, joins the two patches.
  FaultEdges cut(2);
  cut.cells = {1, 4};
  cut.measures.assign(1, 1.0);
  EXPECT_EQ(open_patches({&links, &cut}, open), (std::vector<std::int64_t>{0, 0, -1, 0, 0, -1, 0}));
}

TEST(FaultCells, PatchCompliance)
{
  // Sneddon's mean openings per unit pressure: pi a/E' (2D, length 2a),
  // 16 a/(3 pi E') (a penny of area pi a^2).
  EXPECT_DOUBLE_EQ(patch_compliance(2.0, 1.0e10, 2), M_PI / 1.0e10);
  EXPECT_DOUBLE_EQ(patch_compliance(M_PI * 4.0, 1.0e10, 3), 32 / (3 * M_PI * 1.0e10));
}

TEST(FaultCells, BartonBandisClosure)
{
  // V_m = 1e-4 m, K_ni = 1e10 Pa/m: K_ni V_m = 1e6 Pa.
  const ClosureSpec closure{1.0e-4, 1.0e10};
  EXPECT_DOUBLE_EQ(closure_aperture(closure, 0.0), 1.0e-4);  // unstressed: the largest closure is all there
  EXPECT_DOUBLE_EQ(closure_aperture(closure, -5.0e5), 1.0e-4); // tension counts as 0
  EXPECT_DOUBLE_EQ(closure_aperture(closure, 1.0e6), 5.0e-5);  // s_n = K_ni V_m halves it
  EXPECT_NEAR(closure_aperture(closure, 1.0e12) / (1.0e-4 * 1.0e6 / (1.0e6 + 1.0e12)), 1.0, 1e-14);
  // K_ni is the initial stiffness: the compliance at s_n = 0 is 1/K_ni; and
  // everywhere minus the derivative of the aperture (central differences).
  EXPECT_DOUBLE_EQ(closure_compliance(closure, 0.0), 1.0e-10);
  for (double s : {1.0e5, 1.0e6, 3.0e7})
  {
    const double h = 1e-4 * s;
    const double slope = (closure_aperture(closure, s - h) - closure_aperture(closure, s + h)) / (2 * h);
    EXPECT_NEAR(closure_compliance(closure, s) / slope, 1.0, 1e-7) << "s_n = " << s;
  }
}
