#include "domain/fault_cells.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <span>

namespace biotcontact
{
namespace
{
using Point = std::array<double, 3>;

Point point_of(const InputMesh& mesh, std::int64_t node)
{
  Point p{0, 0, 0};
  std::copy_n(&mesh.x[mesh.dim * node], mesh.dim, p.begin());
  return p;
}

double distance(const Point& a, const Point& b)
{
  return std::hypot(a[0] - b[0], a[1] - b[1], a[2] - b[2]);
}

/// The mean of some nodes' points.
Point mean_of(const InputMesh& mesh, std::span<const std::int64_t> nodes)
{
  Point m{0, 0, 0};
  for (std::int64_t v : nodes)
    for (int i = 0; i < 3; ++i)
      m[i] += point_of(mesh, v)[i] / static_cast<double>(nodes.size());
  return m;
}

/// A cell's measure: a segment's length, a triangle's area.
double cell_measure(const InputMesh& mesh, std::span<const std::int64_t> nodes)
{
  const Point a = point_of(mesh, nodes[0]), b = point_of(mesh, nodes[1]);
  if (nodes.size() == 2)
    return distance(a, b);
  const Point c = point_of(mesh, nodes[2]);
  const Point u{b[0] - a[0], b[1] - a[1], b[2] - a[2]}, v{c[0] - a[0], c[1] - a[1], c[2] - a[2]};
  return 0.5 * std::hypot(u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]);
}

/// The d - 1 node subsets of a cell's sorted nodes (its edges), in the
/// order of Python's itertools.combinations.
std::vector<std::vector<std::int64_t>> edges_of(std::span<const std::int64_t> key)
{
  if (key.size() == 2)
    return {{key[0]}, {key[1]}};
  return {{key[0], key[1]}, {key[0], key[2]}, {key[1], key[2]}};
}

/// The group name of every boundary edge (sorted d - 1 nodes) of the outer
/// boundary's named facets; the first group wins.
std::map<std::vector<std::int64_t>, std::string> boundary_groups(const InputMesh& mesh)
{
  std::map<std::vector<std::int64_t>, std::string> groups;
  const int d = mesh.dim;
  for (std::size_t f = 0; f < mesh.facet_group.size(); ++f)
  {
    std::vector<std::int64_t> facet(&mesh.facets[d * f], &mesh.facets[d * (f + 1)]);
    std::sort(facet.begin(), facet.end());
    for (const auto& edge : edges_of(facet))
      groups.emplace(edge, mesh.names[mesh.facet_group[f]]);
  }
  return groups;
}

/// Appends an edge of `cells` to `edges`.
void add_edge(FaultEdges& edges, const std::vector<std::int64_t>& cells, double measure, const Point& middle,
              const FaultCells& fault)
{
  for (std::int64_t c : cells)
  {
    edges.cells.push_back(c);
    edges.distances.push_back(distance(middle, fault.centroids[c]));
  }
  edges.measures.push_back(measure);
  edges.points.push_back(middle);
}
} // namespace

FaultCells fault_cells(const InputMesh& mesh, const SplitFault& split)
{
  const int d = mesh.dim;
  FaultCells fault;
  for (std::size_t k = 0; k < split.normals.size(); ++k)
  {
    std::span<const std::int64_t> plus(&split.plus_facets[d * k], d), minus(&split.minus_facets[d * k], d);
    if (std::equal(plus.begin(), plus.end(), minus.begin()))
      continue; // not opened: no face (domain/faults.h)
    std::vector<std::pair<std::int64_t, std::int64_t>> nodes; // (+ node, its twin), by + node
    for (int i = 0; i < d; ++i)
      nodes.emplace_back(plus[i], minus[i]);
    std::sort(nodes.begin(), nodes.end());
    std::vector<std::int64_t> key;
    for (const auto& [p, m] : nodes)
      key.push_back(p), fault.twins.push_back(m);
    fault.keys.insert(fault.keys.end(), key.begin(), key.end());
    fault.normals.push_back(split.normals[k]);
    fault.measures.push_back(cell_measure(mesh, key));
    fault.centroids.push_back(mean_of(mesh, key));
    for (std::int64_t v : key)
      fault.vertices.push_back(point_of(mesh, v));
  }
  std::map<std::vector<std::int64_t>, std::vector<std::int64_t>> edges;
  for (std::size_t c = 0; c < fault.size(); ++c)
    for (const auto& edge : edges_of(std::span<const std::int64_t>(&fault.keys[d * c], d)))
      edges[edge].push_back(static_cast<std::int64_t>(c));
  const auto boundary = boundary_groups(mesh);
  for (const auto& [edge, cells] : edges)
  {
    const Point middle = mean_of(mesh, edge);
    const double measure = edge.size() == 1 ? 1.0 : distance(point_of(mesh, edge[0]), point_of(mesh, edge[1]));
    if (cells.size() == 2)
      add_edge(fault.links, cells, measure, middle, fault);
    else if (cells.size() == 1 and boundary.count(edge))
    {
      add_edge(fault.ends, cells, measure, middle, fault);
      fault.end_groups.push_back(boundary.at(edge));
    }
    else if (cells.size() == 1)
      add_edge(fault.inner, cells, measure, middle, fault);
  }
  std::map<Point, std::size_t> first; // the inner edge first met at each midpoint
  for (std::size_t e = 0; e < fault.inner.size(); ++e)
    if (const auto [at, fresh] = first.try_emplace(fault.inner.points[e], e); !fresh)
      add_edge(fault.cut, {fault.inner.cells[at->second], fault.inner.cells[e]}, fault.inner.measures[e],
               fault.inner.points[e], fault);
  return fault;
}

FaultNetwork fault_network(const std::vector<const FaultCells*>& faults)
{
  struct Edge
  {
    std::size_t fault;
    const FaultEdges* edges;
    std::size_t index;
  };
  std::map<Point, std::vector<Edge>> at; // the edges at each midpoint
  for (std::size_t f = 0; f < faults.size(); ++f)
    for (const FaultEdges* edges : {&faults[f]->links, &faults[f]->inner})
      for (std::size_t e = 0; e < edges->size(); ++e)
        at[edges->points[e]].push_back({f, edges, e});
  FaultNetwork network;
  for (std::size_t f = 0; f < faults.size(); ++f)
  {
    const FaultEdges& links = faults[f]->links;
    FaultEdges& kept = network.links.emplace_back(2);
    for (std::size_t e = 0; e < links.size(); ++e)
      if (at.at(links.points[e]).size() == 1) // in the order of the fault's links: the same sums as alone
        add_edge(kept, {links.cells[2 * e], links.cells[2 * e + 1]}, links.measures[e], links.points[e], *faults[f]);
  }
  for (const auto& [point, edges] : at)
  {
    if (edges.size() == 1)
      continue;
    FaultJunction& j = network.junctions.emplace_back(FaultJunction{point, edges[0].edges->measures[edges[0].index]});
    for (const Edge& g : edges)
      for (int i = 0; i < g.edges->width; ++i)
      {
        const std::size_t k = g.edges->width * g.index + i;
        j.faults.push_back(g.fault), j.cells.push_back(g.edges->cells[k]), j.distances.push_back(g.edges->distances[k]);
      }
  }
  return network;
}

namespace
{
/// The distance of point p to the segment from a to b.
double segment_distance(const Point& a, const Point& b, const Point& p)
{
  const Point ab{b[0] - a[0], b[1] - a[1], b[2] - a[2]};
  const double s = std::clamp(((p[0] - a[0]) * ab[0] + (p[1] - a[1]) * ab[1] + (p[2] - a[2]) * ab[2])
                                  / (ab[0] * ab[0] + ab[1] * ab[1] + ab[2] * ab[2]),
                              0.0, 1.0);
  return distance({a[0] + s * ab[0], a[1] + s * ab[1], a[2] + s * ab[2]}, p);
}

/// Whether well w's vertical segment (at (x, y) from z = bottom to top)
/// meets the triangle t[0], t[1], t[2] (its barycentric coordinates within
/// round-off of [0, 1]); a triangle parallel to it is not met.
bool meets_triangle(const Point* t, const WellSpec& w)
{
  const Point &a = t[0], &b = t[1], &c = t[2];
  const double x = w.position[0], y = w.position[1];
  const Point u{b[0] - a[0], b[1] - a[1], b[2] - a[2]}, v{c[0] - a[0], c[1] - a[1], c[2] - a[2]};
  const double det = u[0] * v[1] - u[1] * v[0];
  if (!(std::abs(det) > 1e-12 * (u[0] * u[0] + u[1] * u[1] + u[2] * u[2])))
    return false;
  const double s = ((x - a[0]) * v[1] - (y - a[1]) * v[0]) / det;
  const double r = (u[0] * (y - a[1]) - u[1] * (x - a[0])) / det;
  const double z = a[2] + s * u[2] + r * v[2];
  constexpr double tol = 1e-9;
  return s >= -tol and r >= -tol and s + r <= 1 + tol and z >= w.bottom and z <= w.top;
}
} // namespace

WellOnFault well_cells(const FaultCells& cells, const WellSpec& w)
{
  WellOnFault hit;
  const std::size_t d = cells.size() ? cells.vertices.size() / cells.size() : 0;
  for (std::size_t k = 0; k < cells.size(); ++k)
  {
    const Point* v = &cells.vertices[d * k];
    const bool meets = d == 2 ? segment_distance(v[0], v[1], {w.position[0], w.position[1], 0.0})
                                    <= 1e-6 * cells.measures[k]
                              : meets_triangle(v, w);
    if (meets)
      hit.cells.push_back(static_cast<std::int64_t>(k));
  }
  hit.shares.assign(hit.cells.size(), 1.0 / static_cast<double>(std::max<std::size_t>(hit.cells.size(), 1)));
  return hit;
}

namespace
{
template <typename T>
void share(std::vector<T>& v, MPI_Datatype type, int width, MPI_Comm comm)
{
  long size = static_cast<long>(v.size());
  MPI_Bcast(&size, 1, MPI_LONG, 0, comm);
  v.resize(size);
  MPI_Bcast(v.data(), static_cast<int>(size * width), type, 0, comm);
}

void share_edges(FaultEdges& e, MPI_Comm comm)
{
  share(e.cells, MPI_INT64_T, 1, comm);
  share(e.measures, MPI_DOUBLE, 1, comm);
  share(e.distances, MPI_DOUBLE, 1, comm);
  share(e.points, MPI_DOUBLE, 3, comm);
}
} // namespace

void share_fault_cells(FaultCells& cells, MPI_Comm comm)
{
  share(cells.keys, MPI_INT64_T, 1, comm);
  share(cells.twins, MPI_INT64_T, 1, comm);
  share(cells.normals, MPI_DOUBLE, 3, comm);
  share(cells.measures, MPI_DOUBLE, 1, comm);
  share(cells.centroids, MPI_DOUBLE, 3, comm);
  share(cells.vertices, MPI_DOUBLE, 3, comm);
  share_edges(cells.links, comm);
  share_edges(cells.ends, comm);
  share_edges(cells.inner, comm);
  share_edges(cells.cut, comm);
  std::string groups;
  for (const std::string& g : cells.end_groups)
    groups += g + "\n";
  std::vector<char> text(groups.begin(), groups.end());
  share(text, MPI_CHAR, 1, comm);
  cells.end_groups.clear();
  for (std::size_t start = 0, end; (end = std::string_view(text.data(), text.size()).find('\n', start))
                                   != std::string_view::npos;
       start = end + 1)
    cells.end_groups.emplace_back(text.data() + start, end - start);
}

} // namespace biotcontact
