#include "domain/faults.h"

#include "domain/mesh_topology.h"

#include "scene/input.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <set>
#include <sstream>

namespace biotcontact
{
namespace
{

/// The mean of `count` nodes' coordinates (a node, a facet's midpoint, a
/// cell's centroid), z = 0 in 2D.
std::array<double, 3> mean_point(const InputMesh& mesh, const std::int64_t* nodes, int count)
{
  std::array<double, 3> p{0, 0, 0};
  for (int k = 0; k < count; ++k)
    for (int i = 0; i < mesh.dim; ++i)
      p[i] += mesh.x[nodes[k] * mesh.dim + i] / count;
  return p;
}

/// "(x, y)" or "(x, y, z)", as the prototype prints it ({:g}).
std::string point_text(const std::array<double, 3>& p, int d)
{
  std::ostringstream s;
  s << "(" << p[0] << ", " << p[1];
  if (d == 3)
    s << ", " << p[2];
  s << ")";
  return s.str();
}

double dot(const std::array<double, 3>& a, const std::array<double, 3>& b)
{
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

/// A facet's unit normal, either way: 2D, its segment turned by -90
/// degrees; 3D, the cross product of its edges from the first node.
std::array<double, 3> facet_normal(const InputMesh& mesh, const std::int64_t* nodes)
{
  const int d = mesh.dim;
  std::array<std::array<double, 3>, 2> edge{};
  for (int k = 0; k + 1 < d; ++k)
    for (int i = 0; i < d; ++i)
      edge[k][i] = mesh.x[nodes[k + 1] * d + i] - mesh.x[nodes[0] * d + i];
  const auto& [a, b] = edge;
  std::array<double, 3> n = d == 2 ? std::array<double, 3>{a[1], -a[0], 0}
                                   : std::array<double, 3>{a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2],
                                                           a[0] * b[1] - a[1] * b[0]};
  const double length = std::sqrt(dot(n, n));
  for (double& v : n)
    v /= length;
  return n;
}

/// @brief A fault's facets before the split: their input indices (in input
/// order), normals oriented by the hint, and the cell on each side.
struct OrientedFault
{
  std::vector<std::size_t> facets;
  std::vector<std::array<double, 3>> normals;
  std::vector<std::int64_t> plus_cells, minus_cells;
};

/// The index of the group `name` in the mesh's names.
std::int32_t group_index(const InputMesh& mesh, const std::string& name, const std::string& key)
{
  const auto it = std::find(mesh.names.begin(), mesh.names.end(), name);
  if (it != mesh.names.end())
    return static_cast<std::int32_t>(it - mesh.names.begin());
  std::string known;
  for (const std::string& n : mesh.names)
    known += (known.empty() ? "" : ", ") + n;
  throw SceneError(key + ": the mesh has no group " + name + " (its facet groups: "
                   + (known.empty() ? "none" : known) + ")");
}

/// How far cell `cell`'s centroid lies from the facet through `nodes`,
/// along n: the + cell is the one on the side n points into.
double side(const InputMesh& mesh, const InputTopology& t, std::int64_t cell, const std::int64_t* nodes,
            const std::array<double, 3>& n)
{
  const std::array<double, 3> centroid = mean_point(mesh, &t.cells[cell * (t.d + 1)], t.d + 1);
  const std::array<double, 3> on = mean_point(mesh, nodes, 1);
  return dot(n, {centroid[0] - on[0], centroid[1] - on[1], centroid[2] - on[2]});
}

/// The facets of the group `request.name`, each between two cells, with
/// its normal oriented by the hint (scaled to unit length, so that the
/// parallel test does not depend on its length) and its + and - cells.
OrientedFault orient_fault(const InputMesh& mesh, const InputTopology& t, const FaultRequest& request,
                           const std::string& key)
{
  const int d = mesh.dim;
  const std::int32_t group = group_index(mesh, request.name, key);
  const double length = std::sqrt(dot(request.hint, request.hint));
  const std::array<double, 3> hint = length > 0 ? std::array<double, 3>{request.hint[0] / length,
                                                                         request.hint[1] / length,
                                                                         request.hint[2] / length}
                                                : request.hint;
  OrientedFault fault;
  for (std::size_t f = 0; f < mesh.facet_group.size(); ++f)
  {
    if (mesh.facet_group[f] != group)
      continue;
    const std::int64_t* nodes = &mesh.facets[f * d];
    const std::vector<std::int64_t> cells = cells_of(t, facet_key(nodes, d));
    const std::string at = " at " + point_text(mean_point(mesh, nodes, d), d);
    if (cells.size() == 1)
      throw SceneError(key + ": the group " + request.name + " lies on the outer boundary" + at
                       + " (a fault is inside the body)");
    if (cells.size() != 2)
    {
      const std::string embed = d == 2 ? "Curve{..} In Surface{..}" : "Surface{..} In Volume{..}";
      throw SceneError(key + ": the group " + request.name + " is not in the mesh's cells (its facets are no faces "
                       + "of them): embed it (gmsh: " + embed + ")");
    }
    std::array<double, 3> n = facet_normal(mesh, nodes);
    const double along = dot(n, hint);
    if (std::abs(along) < 1e-12)
      throw SceneError(key + ".normal: the hint is parallel to the fault" + at + ": give a normal that crosses it");
    if (along < 0)
      n = {-n[0], -n[1], -n[2]};
    const bool first_plus = side(mesh, t, cells[0], nodes, n) > side(mesh, t, cells[1], nodes, n);
    fault.facets.push_back(f);
    fault.normals.push_back(n);
    fault.plus_cells.push_back(cells[first_plus ? 0 : 1]);
    fault.minus_cells.push_back(cells[first_plus ? 1 : 0]);
  }
  if (fault.facets.empty())
    throw SceneError(key + ": the group " + request.name + " has no facets");
  return fault;
}

/// The fault facets through each fault node, (fault, facet k), by node in
/// increasing order; within a node, in request order.
using FaultNodes = std::map<std::int64_t, std::vector<std::pair<std::size_t, std::size_t>>>;

FaultNodes fault_nodes(const InputMesh& mesh, const std::vector<OrientedFault>& faults)
{
  FaultNodes nodes;
  for (std::size_t f = 0; f < faults.size(); ++f)
    for (std::size_t k = 0; k < faults[f].facets.size(); ++k)
      for (int i = 0; i < mesh.dim; ++i)
        nodes[mesh.facets[faults[f].facets[k] * mesh.dim + i]].emplace_back(f, k);
  return nodes;
}

/// Refuses a facet in two faults' groups: one curve (3D: surface) given
/// to two physical groups, which the split could not give two faults.
void refuse_shared_facets(const InputMesh& mesh, const std::vector<OrientedFault>& oriented,
                          const std::vector<FaultRequest>& faults, const std::string& key_prefix)
{
  std::map<FacetKey, std::size_t> fault_of;
  for (std::size_t f = 0; f < oriented.size(); ++f)
    for (std::size_t facet : oriented[f].facets)
    {
      const std::int64_t* nodes = &mesh.facets[facet * mesh.dim];
      const auto [it, added] = fault_of.emplace(facet_key(nodes, mesh.dim), f);
      if (!added and it->second != f)
        throw SceneError(key_prefix + faults[it->second].name + ": the physical groups " + faults[it->second].name
                         + " and " + faults[f].name + " share the facet at "
                         + point_text(mean_point(mesh, nodes, mesh.dim), mesh.dim) + ": a "
                         + (mesh.dim == 2 ? "curve" : "surface") + " belongs to one fault's group only");
    }
}

/// The facets of all faults, sorted.
std::vector<FacetKey> fault_keys(const InputMesh& mesh, const std::vector<OrientedFault>& faults)
{
  std::vector<FacetKey> keys;
  for (const OrientedFault& fault : faults)
    for (std::size_t f : fault.facets)
      keys.push_back(facet_key(&mesh.facets[f * mesh.dim], mesh.dim));
  std::sort(keys.begin(), keys.end());
  return keys;
}

/// @brief The cells around a node (ascending) and the component of each:
/// cells connected through the facets that hold the node and lie on no
/// fault, numbered in the order of their first cell.
struct NodeStar
{
  std::vector<std::int64_t> cells;
  std::vector<int> component;
  int count = 0;
};

/// The cells that share with `cell` a facet through node v on no fault.
std::vector<std::int64_t> neighbours(const InputTopology& t, std::int64_t cell, std::int64_t v,
                                     const std::vector<FacetKey>& keys)
{
  const std::int64_t* nodes = &t.cells[cell * (t.d + 1)];
  std::vector<std::int64_t> found;
  for (int j = 0; j <= t.d; ++j)
  {
    if (nodes[j] == v)
      continue;
    std::array<std::int64_t, 3> facet{-1, -1, -1};
    std::copy_if(nodes, nodes + t.d + 1, facet.begin(), [&](std::int64_t u) { return u != nodes[j]; });
    const FacetKey key = facet_key(facet.data(), t.d);
    if (std::binary_search(keys.begin(), keys.end(), key))
      continue;
    for (std::int64_t other : cells_of(t, key))
      if (other != cell)
        found.push_back(other);
  }
  return found;
}

NodeStar star_of(const InputTopology& t, std::int64_t v, const std::vector<FacetKey>& keys)
{
  NodeStar star;
  star.cells.assign(t.node_cells.begin() + t.node_offsets[v], t.node_cells.begin() + t.node_offsets[v + 1]);
  star.component.assign(star.cells.size(), -1);
  for (std::size_t first = 0; first < star.cells.size(); ++first)
  {
    if (star.component[first] >= 0)
      continue;
    star.component[first] = star.count;
    std::vector<std::int64_t> stack{star.cells[first]};
    while (!stack.empty())
    {
      const std::int64_t cell = stack.back();
      stack.pop_back();
      for (std::int64_t other : neighbours(t, cell, v, keys))
      {
        const auto i = std::lower_bound(star.cells.begin(), star.cells.end(), other) - star.cells.begin();
        if (star.component[i] < 0)
        {
          star.component[i] = star.count;
          stack.push_back(other);
        }
      }
    }
    ++star.count;
  }
  return star;
}

int component_of(const NodeStar& star, std::int64_t cell)
{
  return star.component[std::lower_bound(star.cells.begin(), star.cells.end(), cell) - star.cells.begin()];
}

/// Refuses + and - cells of the fault's facets through a split node v
/// (`facets`) in one component of its star: the hint's side of the fault
/// flips at v. Where each facet's two cells hold together, v is on the
/// fault's edge (a tip line that crosses another fault, in 3D), which
/// another fault split: nothing to check.
void check_sides(const InputMesh& mesh, const NodeStar& star, const OrientedFault& fault,
                 const std::vector<std::size_t>& facets, std::int64_t v, const std::string& key)
{
  std::set<int> plus, minus;
  bool separates = false;
  for (std::size_t k : facets)
  {
    plus.insert(component_of(star, fault.plus_cells[k]));
    minus.insert(component_of(star, fault.minus_cells[k]));
    separates = separates or component_of(star, fault.plus_cells[k]) != component_of(star, fault.minus_cells[k]);
  }
  if (!separates)
    return;
  for (int c : plus)
    if (minus.count(c))
      throw SceneError(key + ": the normal hint orients the fault inconsistently at "
                       + point_text(mean_point(mesh, &v, 1), mesh.dim)
                       + " (the fault turns past the hint there: give a hint that crosses all of it the same way)");
}

/// Appends a copy of node v to x and returns its index.
std::int64_t append_node(InputMesh& mesh, std::int64_t v)
{
  const int d = mesh.dim;
  const auto index = static_cast<std::int64_t>(mesh.x.size()) / d;
  for (int i = 0; i < d; ++i)
  {
    const double coordinate = mesh.x[v * d + i];
    mesh.x.push_back(coordinate);
  }
  return index;
}

/// @brief The split of the fault nodes, one node at a time: the input mesh
/// (renumbered in place), its topology, the oriented faults and their
/// facets, and the faults' results so far.
class Splitter
{
public:
  Splitter(InputMesh& mesh, const InputTopology& t, const std::vector<OrientedFault>& faults,
           const std::string& key_prefix, std::vector<SplitFault>& split)
      : _mesh(mesh), _t(t), _faults(faults), _key_prefix(key_prefix), _split(split), _keys(fault_keys(mesh, faults))
  {
  }

  /// Node v gets one node per component of its star (the cells around it
  /// that the faults leave connected); each fault's facets through v pair
  /// the nodes of their + and - cells' components (a tip where they are one).
  void split_node(std::int64_t v, const std::vector<std::pair<std::size_t, std::size_t>>& through)
  {
    const NodeStar star = star_of(_t, v, _keys);
    std::map<std::size_t, std::vector<std::size_t>> by_fault; // request order: ascending
    for (const auto& [f, k] : through)
      by_fault[f].push_back(k);
    if (star.count > 2 and by_fault.size() == 1)
      throw SceneError(_key_prefix + _split[through.front().first].name + ": the fault branches or crosses itself at "
                       + point_text(mean_point(_mesh, &v, 1), _mesh.dim) + " (" + std::to_string(star.count)
                       + " pieces meet there): give each branch a fault (a physical group) of its own");
    std::vector<std::int64_t> node_of{v};
    if (star.count > 1)
    {
      for (const auto& [f, facets] : by_fault)
        check_sides(_mesh, star, _faults[f], facets, v, _key_prefix + _split[f].name);
      const auto& [f0, k0] = through.front();
      node_of = copies(star, _faults[f0].minus_cells[k0], v);
    }
    for (std::size_t i = 0; i < star.cells.size(); ++i)
      _mesh.cells[star.cells[i] * (_t.d + 1) + local_index(_t, star.cells[i], v)] = node_of[star.component[i]];
    for (const auto& [f, facets] : by_fault)
      add_pairs(star, node_of, {f, facets}, v, by_fault);
  }

private:
  /// The node of each component of v's star: v itself for the component of
  /// the cell `first` (with one fault, its - side), a new node at v's point
  /// for each other, in the order of the components.
  std::vector<std::int64_t> copies(const NodeStar& star, std::int64_t first, std::int64_t v)
  {
    const int keep = component_of(star, first);
    std::vector<std::int64_t> node_of;
    for (int c = 0; c < star.count; ++c)
      node_of.push_back(c == keep ? v : append_node(_mesh, v));
    return node_of;
  }

  /// Fault f's pairs at v (its facets' + and - nodes where they differ), or
  /// v as its tip (each copy of v on f where other faults split v: a rim
  /// crossing another fault); the other faults through v as the ones it meets.
  void add_pairs(const NodeStar& star, const std::vector<std::int64_t>& node_of,
                 const std::pair<std::size_t, const std::vector<std::size_t>&>& fault, std::int64_t v,
                 const std::map<std::size_t, std::vector<std::size_t>>& by_fault)
  {
    const auto& [f, facets] = fault;
    SplitFault& result = _split[f];
    const std::size_t before = result.pairs.size();
    for (std::size_t k : facets)
    {
      const std::pair<std::int64_t, std::int64_t> pair{node_of[component_of(star, _faults[f].plus_cells[k])],
                                                       node_of[component_of(star, _faults[f].minus_cells[k])]};
      if (pair.first != pair.second
          and std::find(result.pairs.begin() + before, result.pairs.end(), pair) == result.pairs.end())
        result.pairs.push_back(pair);
    }
    const std::size_t tips = result.tips.size();
    if (result.pairs.size() == before)
      for (std::size_t k : facets)
      {
        const std::int64_t tip = node_of[component_of(star, _faults[f].plus_cells[k])];
        if (std::find(result.tips.begin() + tips, result.tips.end(), tip) == result.tips.end())
          result.tips.push_back(tip);
      }
    for (const auto& [g, unused] : by_fault)
      if (g != f)
        result.meets.emplace_back(v, g);
  }

  InputMesh& _mesh;
  const InputTopology& _t;
  const std::vector<OrientedFault>& _faults;
  const std::string& _key_prefix;
  std::vector<SplitFault>& _split;
  const std::vector<FacetKey> _keys;
};

/// Each fault node (in increasing order) stays shared where the faults'
/// cells around it hold together (a tip), or gets one node per piece of its
/// star (two on one fault: its + side's cells take a new node; three or
/// four where faults cross or end on one another).
void split_nodes(InputMesh& mesh, const InputTopology& t, const std::vector<OrientedFault>& faults,
                 const FaultNodes& nodes, const std::string& key_prefix, std::vector<SplitFault>& split)
{
  Splitter splitter(mesh, t, faults, key_prefix, split);
  for (const auto& [v, through] : nodes)
    splitter.split_node(v, through);
}

/// Appends the input facet through `nodes` as cell `cell` numbers it after
/// the split.
void append_face(const InputMesh& mesh, const InputTopology& t, std::int64_t cell, const std::int64_t* nodes,
                 std::vector<std::int64_t>& faces)
{
  for (int i = 0; i < t.d; ++i)
    faces.push_back(mesh.cells[cell * (t.d + 1) + local_index(t, cell, nodes[i])]);
}

/// A fault's two faces after the split, from its + and - cells.
void fault_faces(const InputMesh& mesh, const InputTopology& t, const OrientedFault& fault, SplitFault& split)
{
  for (std::size_t k = 0; k < fault.facets.size(); ++k)
  {
    const std::int64_t* nodes = &mesh.facets[fault.facets[k] * t.d];
    append_face(mesh, t, fault.plus_cells[k], nodes, split.plus_facets);
    append_face(mesh, t, fault.minus_cells[k], nodes, split.minus_facets);
  }
}

/// Keeps the facets of no fault, each as its (first) cell numbers it after
/// the split: where a fault reaches the outer boundary, the boundary
/// splits with it. A facet that is no face of a cell is kept as it is.
void renumber_facets(InputMesh& mesh, const InputTopology& t, const std::vector<bool>& on_fault)
{
  std::vector<std::int64_t> facets;
  std::vector<std::int32_t> groups;
  for (std::size_t f = 0; f < mesh.facet_group.size(); ++f)
  {
    if (on_fault[f])
      continue;
    const std::int64_t* nodes = &mesh.facets[f * t.d];
    const std::vector<std::int64_t> cells = cells_of(t, facet_key(nodes, t.d));
    if (cells.empty())
      facets.insert(facets.end(), nodes, nodes + t.d);
    else
      append_face(mesh, t, cells.front(), nodes, facets);
    groups.push_back(mesh.facet_group[f]);
  }
  mesh.facets = std::move(facets);
  mesh.facet_group = std::move(groups);
}

} // namespace

std::vector<SplitFault> split_along_faults(InputMesh& mesh, const std::vector<FaultRequest>& faults,
                                           const std::string& key_prefix)
{
  const InputTopology topology = topology_of(mesh.dim, mesh.cells, mesh.x.size() / mesh.dim);
  std::vector<OrientedFault> oriented;
  std::vector<SplitFault> split;
  for (const FaultRequest& request : faults)
  {
    oriented.push_back(orient_fault(mesh, topology, request, key_prefix + request.name));
    split.push_back({request.name, {}, {}, oriented.back().normals, {}, {}, {}});
  }
  refuse_shared_facets(mesh, oriented, faults, key_prefix);
  const FaultNodes nodes = fault_nodes(mesh, oriented);
  split_nodes(mesh, topology, oriented, nodes, key_prefix, split);
  std::vector<bool> on_fault(mesh.facet_group.size(), false);
  for (std::size_t f = 0; f < oriented.size(); ++f)
  {
    fault_faces(mesh, topology, oriented[f], split[f]);
    for (std::size_t facet : oriented[f].facets)
      on_fault[facet] = true;
    std::sort(split[f].tips.begin(), split[f].tips.end()); // a tip's copies come after the input's nodes
  }
  renumber_facets(mesh, topology, on_fault);
  return split;
}

} // namespace biotcontact
