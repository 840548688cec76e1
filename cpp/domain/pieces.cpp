#include "domain/pieces.h"

#include "scene/input.h"

#include <algorithm>
#include <cmath>
#include <numeric>

namespace biotcontact
{

namespace
{

/// @brief A constraint on a piece's motion along n at x: against the
/// ground (other = -1) or against another piece.
struct Constraint
{
  std::int64_t piece, other;
  std::array<double, 3> x, n;
};

std::array<double, 3> point(const InputMesh& mesh, std::int64_t node)
{
  std::array<double, 3> p{0, 0, 0};
  std::copy_n(&mesh.x[mesh.dim * node], mesh.dim, p.begin());
  return p;
}

/// The normal of a facet (dim nodes), not normalised: its direction is all
/// a constraint needs.
std::array<double, 3> facet_normal(const InputMesh& mesh, const std::int64_t* nodes)
{
  const auto a = point(mesh, nodes[0]), b = point(mesh, nodes[1]);
  if (mesh.dim == 2)
    return {a[1] - b[1], b[0] - a[0], 0};
  const auto c = point(mesh, nodes[2]);
  const std::array<double, 3> u{b[0] - a[0], b[1] - a[1], b[2] - a[2]}, v{c[0] - a[0], c[1] - a[1], c[2] - a[2]};
  return {u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]};
}

/// Adds the constraint along n at node, or along every axis (`every`).
void constrain(std::vector<Constraint>& rows, const InputMesh& mesh, std::array<std::int64_t, 3> where,
               const std::array<double, 3>& n, bool every)
{
  const auto [piece, other, node] = where;
  if (!every)
    rows.push_back({piece, other, point(mesh, node), n});
  for (int i = 0; i < mesh.dim and every; ++i)
  {
    std::array<double, 3> e{0, 0, 0};
    e[i] = 1;
    rows.push_back({piece, other, point(mesh, node), e});
  }
}

bool frictional(const FrictionSpec& f) { return f.friction > 0 or f.cohesion > 0 or f.tresca; }

/// The ground's constraints: clamps and prescribed components, and
/// foundations (along the facet's normal; every way with friction).
void boundary_constraints(const Scene& scene, const InputMesh& mesh, const std::vector<std::int64_t>& piece,
                          std::vector<Constraint>& rows)
{
  const int d = mesh.dim;
  for (std::size_t k = 0; k < mesh.facet_group.size(); ++k)
  {
    const auto b = scene.boundaries.find(mesh.names[mesh.facet_group[k]]);
    if (b == scene.boundaries.end())
      continue;
    const std::int64_t* nodes = &mesh.facets[d * k];
    const BoundarySpec& spec = b->second;
    for (int i = 0; i < d; ++i)
    {
      const std::int64_t node = nodes[i];
      if (spec.mechanics == BoundarySpec::Mechanics::contact)
        constrain(rows, mesh, {piece[node], -1, node}, facet_normal(mesh, nodes), frictional(spec.contact->friction));
      for (int c = 0; c < d and spec.mechanics == BoundarySpec::Mechanics::displacement; ++c)
      {
        std::array<double, 3> e{0, 0, 0};
        e[c] = 1;
        if (spec.displacement[c])
          rows.push_back({piece[node], -1, point(mesh, node), e});
      }
    }
  }
}

/// Each fault's pairs: the + node's piece against the - node's, along the
/// fault's normal (every way with friction).
void fault_constraints(const Scene& scene, const InputMesh& mesh, const std::vector<SplitFault>& faults,
                       const std::vector<std::int64_t>& piece, std::vector<Constraint>& rows)
{
  const int d = mesh.dim;
  for (const SplitFault& f : faults)
  {
    const bool every = frictional(scene.faults.at(f.name).friction);
    for (std::size_t k = 0; k < f.normals.size(); ++k)
      for (int i = 0; i < d; ++i)
      {
        const std::int64_t plus = f.plus_facets[d * k + i], minus = f.minus_facets[d * k + i];
        if (plus != minus)
          constrain(rows, mesh, {piece[plus], piece[minus], plus}, f.normals[k], every);
      }
  }
}

/// Whether piece p is held by the rows against the ground and held pieces.
bool held(const InputMesh& mesh, std::int64_t p, const std::vector<Constraint>& rows, const std::vector<char>& is_held)
{
  std::vector<double> points, directions;
  std::array<double, 3> low{HUGE_VAL, HUGE_VAL, HUGE_VAL}, high{-HUGE_VAL, -HUGE_VAL, -HUGE_VAL};
  for (const Constraint& r : rows)
  {
    const bool against_held = r.piece == p and (r.other < 0 or is_held[r.other]);
    if (!against_held and !(r.other == p and is_held[r.piece]))
      continue;
    points.insert(points.end(), r.x.begin(), r.x.begin() + mesh.dim);
    directions.insert(directions.end(), r.n.begin(), r.n.begin() + mesh.dim);
    for (int i = 0; i < 3; ++i)
      low[i] = std::min(low[i], r.x[i]), high[i] = std::max(high[i], r.x[i]);
  }
  if (points.empty())
    return false;
  std::array<double, 3> centre;
  double size = 0;
  for (int i = 0; i < 3; ++i)
    centre[i] = 0.5 * (low[i] + high[i]), size = std::max(size, high[i] - low[i]);
  const int motions = mesh.dim == 2 ? 3 : 6;
  return held_motions(points, directions, mesh.dim, centre, size > 0 ? size : 1.0) == motions;
}

/// "the piece on its + side of fault.NAME around (x, y)" for the first
/// fault face in piece p.
std::string piece_text(const Scene& scene, const InputMesh& mesh, const std::vector<SplitFault>& faults,
                       const std::vector<std::int64_t>& piece, std::int64_t p)
{
  for (const SplitFault& f : faults)
    for (std::size_t i = 0; i < f.plus_facets.size(); ++i)
      for (const auto& [nodes, side] : {std::pair{&f.plus_facets, "+"}, std::pair{&f.minus_facets, "-"}})
        if (f.plus_facets[i] != f.minus_facets[i] and piece[(*nodes)[i]] == p)
          return scene.file + ": fault." + f.name + ": the piece on its " + side + " side (its node at "
                 + point_text(point(mesh, (*nodes)[i]).data(), mesh.dim) + ")";
  return scene.file + ": mesh: a piece of the mesh";
}

} // namespace

std::vector<std::int64_t> mesh_pieces(const InputMesh& mesh)
{
  const std::size_t nodes = mesh.x.size() / mesh.dim;
  std::vector<std::int64_t> parent(nodes);
  std::iota(parent.begin(), parent.end(), 0);
  auto root = [&](std::int64_t k)
  {
    while (parent[k] != k)
      k = parent[k] = parent[parent[k]];
    return k;
  };
  const int n = mesh.dim + 1;
  for (std::size_t c = 0; c < mesh.cells.size(); c += n)
    for (int i = 1; i < n; ++i)
      parent[root(mesh.cells[c + i])] = root(mesh.cells[c]);
  std::vector<std::int64_t> number(nodes, -1), piece(nodes, -1);
  std::int64_t pieces = 0;
  for (std::size_t c = 0; c < mesh.cells.size(); c += n)
    if (number[root(mesh.cells[c])] < 0)
      number[root(mesh.cells[c])] = pieces++;
  for (std::size_t k = 0; k < nodes; ++k)
    piece[k] = number[root(k)];
  return piece;
}

int held_motions(const std::vector<double>& points, const std::vector<double>& directions, int dim,
                 const std::array<double, 3>& centre, double size)
{
  const int m = dim == 2 ? 3 : 6;
  std::vector<double> G(m * m, 0.0); // the Gram matrix of the rows
  for (std::size_t r = 0; r < points.size() / dim; ++r)
  {
    const double* x = &points[dim * r];
    const double* n = &directions[dim * r];
    const double X = (x[0] - centre[0]) / size, Y = (x[1] - centre[1]) / size;
    const double Z = dim == 3 ? (x[2] - centre[2]) / size : 0.0, nz = dim == 3 ? n[2] : 0.0;
    std::vector<double> row{n[0], n[1]};
    if (dim == 2)
      row.push_back(-Y * n[0] + X * n[1]);
    else
      row.insert(row.end(), {nz, -Z * n[1] + Y * nz, Z * n[0] - X * nz, -Y * n[0] + X * n[1]});
    for (int i = 0; i < m; ++i)
      for (int j = 0; j < m; ++j)
        G[m * i + j] += row[i] * row[j];
  }
  // Rank by Cholesky with diagonal pivoting, pivots below 1e-10 of the
  // largest diagonal counted as zero.
  const double floor = 1e-10 * *std::max_element(G.begin(), G.end());
  std::vector<char> used(m, 0);
  int rank = 0;
  for (int step = 0; step < m; ++step)
  {
    int k = -1;
    for (int i = 0; i < m; ++i)
      if (!used[i] and (k < 0 or G[m * i + i] > G[m * k + k]))
        k = i;
    if (!(G[m * k + k] > floor))
      break;
    used[k] = 1, ++rank;
    const double pivot = G[m * k + k];
    for (int i = 0; i < m; ++i)
      for (int j = 0; j < m; ++j)
        if (!used[i] and !used[j])
          G[m * i + j] -= G[m * i + k] * G[m * k + j] / pivot;
  }
  return rank;
}

void refuse_free_pieces(const Scene& scene, const InputMesh& mesh, const std::vector<SplitFault>& faults)
{
  if (!scene.mechanics)
    return;
  const std::vector<std::int64_t> piece = mesh_pieces(mesh);
  const std::int64_t pieces = *std::max_element(piece.begin(), piece.end()) + 1;
  std::vector<Constraint> rows;
  boundary_constraints(scene, mesh, piece, rows);
  fault_constraints(scene, mesh, faults, piece, rows);
  std::vector<char> is_held(pieces, 0);
  for (bool changed = true; changed;)
  {
    changed = false;
    for (std::int64_t p = 0; p < pieces; ++p)
      if (!is_held[p] and held(mesh, p, rows, is_held))
        is_held[p] = 1, changed = true;
  }
  const auto free = std::find(is_held.begin(), is_held.end(), 0);
  if (free == is_held.end())
    return;
  throw SceneError(piece_text(scene, mesh, faults, piece, free - is_held.begin())
                   + " is free to move as a rigid body: no clamp, displacement, foundation or fault with friction "
                     "holds all its rigid motions (a frictionless fault holds only its normal); hold it with a "
                     "displacement boundary, or give the fault friction");
}

} // namespace biotcontact
