#include "contact/fault_pair.h"

#include "assembly/fault_aperture.h"
#include "assembly/linear_algebra.h"

#include <dolfinx/fem/DirichletBC.h>
#include <dolfinx/fem/FunctionSpace.h>
#include <algorithm>
#include <cmath>
#include <map>
#include <set>

namespace biotcontact
{
using namespace dolfinx;

namespace
{
/// @brief One fault's data for its constraints: its name and index among
/// the contact's boundaries, its scene entry, and per node of its + face
/// the lumped measure and the node in the output space.
struct FaultFace
{
  std::string name;
  const Fault& fault;
  int boundary;
  const FaultSpec& spec;
  la::Vector<double> lumped;
  std::map<std::int32_t, std::int32_t> output_dof; // first DOF in V -> node in c.output_space
};

/// @brief Where faults cross or end on one another: each junction's nodes
/// (input indices, one per piece around it, sorted) and its pairs (fault,
/// pair index), and of each pair at a junction its junction and the row of
/// its + node that carries its constraint.
struct Junctions
{
  std::vector<std::vector<std::int64_t>> nodes;
  std::vector<std::vector<std::pair<std::string, std::size_t>>> pairs;
  std::map<std::pair<std::string, std::size_t>, std::pair<std::size_t, int>> of_pair; // -> (junction, row)
};

/// The representative of node v in a union-find forest.
std::int64_t root(std::map<std::int64_t, std::int64_t>& parent, std::int64_t v)
{
  while (parent.at(v) != v)
    v = parent[v] = parent.at(parent.at(v));
  return v;
}

/// The junctions of the faults: the pieces of the graph whose edges are
/// the node pairs of every fault that hold more than one pair (a lone
/// pair is its two nodes). Each pair takes the next free row of its +
/// node, in the faults' order.
Junctions fault_junctions(const Domain& domain)
{
  std::map<std::int64_t, std::int64_t> parent;
  for (const auto& [name, fault] : domain.faults)
    for (const auto& pair : fault.pairs)
    {
      for (const std::int64_t v : pair)
        parent.emplace(v, v);
      parent[root(parent, pair[0])] = root(parent, pair[1]);
    }
  std::map<std::int64_t, std::vector<std::pair<std::string, std::size_t>>> by_root;
  for (const auto& [name, fault] : domain.faults)
    for (std::size_t k = 0; k < fault.pairs.size(); ++k)
      by_root[root(parent, fault.pairs[k][0])].emplace_back(name, k);
  Junctions j;
  std::map<std::int64_t, int> rows; // + node -> rows taken
  for (const auto& [r, pairs] : by_root)
  {
    if (pairs.size() < 2)
      continue;
    std::set<std::int64_t> nodes;
    for (const auto& [name, k] : pairs)
    {
      const auto& pair = domain.faults.at(name).pairs[k];
      nodes.insert(pair.begin(), pair.end());
      j.of_pair[{name, k}] = {j.nodes.size(), rows[pair[0]]++};
    }
    j.nodes.emplace_back(nodes.begin(), nodes.end());
    j.pairs.push_back(pairs);
  }
  return j;
}

/// The pairs of junction i as its block sees them.
std::vector<JunctionPair> junction_pairs(const Domain& domain, const Junctions& j, std::size_t i)
{
  const std::vector<std::int64_t>& around = j.nodes[i];
  const auto position = [&](std::int64_t v)
  { return static_cast<int>(std::lower_bound(around.begin(), around.end(), v) - around.begin()); };
  std::vector<JunctionPair> pairs;
  for (const auto& [name, k] : j.pairs[i])
  {
    const Fault& fault = domain.faults.at(name);
    const std::array<double, 3>& n = fault.normals[k];
    pairs.push_back({position(fault.pairs[k][0]), position(fault.pairs[k][1]), j.of_pair.at({name, k}).second,
                     {-n[0], -n[1], -n[2]}});
  }
  return pairs;
}

/// What makes junction i impossible to pose (empty when nothing does): a
/// piece on the + side of more than d of its pairs, or constraints that
/// are not independent (faces meeting parallel).
std::string junction_problem(const Domain& domain, const Junctions& j, std::size_t i)
{
  const std::vector<JunctionPair> pairs = junction_pairs(domain, j, i);
  const int d = domain.dim();
  for (const JunctionPair& p : pairs)
    if (p.row >= d)
      return "a piece between the faults is on the + side of more than " + std::to_string(d)
             + " of their faces (orient them by their normals so that no piece is)";
  if (!junction_change_of_variables(pairs, static_cast<int>(j.nodes[i].size()), d))
    return "the faults' faces there are parallel, so their contact constraints are not independent";
  return {};
}

/// The block of T at junction i, in V's numbering (its problems found).
void add_junction_block(ContactSet& c, const Domain& domain, const FaultNodes& nodes, const Junctions& j,
                        std::size_t i)
{
  const std::vector<JunctionPair> pairs = junction_pairs(domain, j, i);
  ContactBlock block{{}, *junction_change_of_variables(pairs, static_cast<int>(j.nodes[i].size()), c.dim)};
  for (const std::int64_t v : j.nodes[i])
    for (int d = 0; d < c.dim; ++d)
      block.dofs.push_back(c.dim * nodes.global.at(v) + d);
  c.blocks.push_back(std::move(block));
}

/// @brief What every pair's constraint reads: the scene file (for
/// messages), the coordinates of V's nodes, its prescribed DOFs, where the
/// fault nodes are, the nodes (local) that a foundation's constraint
/// holds, and the faults' junctions.
struct PairContext
{
  const std::string& file;
  const Domain& domain;
  std::vector<double> coordinates;
  std::vector<char> prescribed;
  FaultNodes nodes;
  std::set<std::int32_t> on_foundation;
  Junctions junctions;
};

/// The local nodes of this rank's foundation constraints (those in c so far).
std::set<std::int32_t> foundation_nodes(const ContactSet& c)
{
  std::set<std::int32_t> nodes;
  for (std::size_t k = 0; k < c.dofs.size(); ++k)
    if (c.pair_node[k] < 0)
      nodes.insert(c.dofs[k] / c.dim);
  return nodes;
}

/// Appends constraint k of `face` to c: its row `first` (of the + node), gap
/// g, frame R and whether friction acts on it.
void push_constraint(ContactSet& c, const FaultFace& face, std::size_t k, std::int32_t first,
                     std::pair<double, const NodeMatrix&> gap_frame, bool frictional)
{
  const std::int32_t node = first - first % c.dim;
  c.dofs.push_back(first);
  c.sign.push_back(1);
  c.gap.push_back(gap_frame.first);
  c.lumped.push_back(face.lumped.array()[node]);
  c.normal.push_back(face.fault.normals[k]);
  c.boundary.push_back(face.boundary);
  c.pair_node.push_back(face.fault.pairs[k][0]);
  c.pair_frame.push_back(gap_frame.second);
  c.frictional.push_back(frictional);
  c.output_dofs.push_back(face.output_dof.at(node));
  c.junction_nodes.push_back({-1, -1});
}

/// The constraint of pair k where it meets other faults' pairs: the next
/// free row of its + node (fault_junctions), frictionless, its slip
/// measured on u; the first pair of its junction brings the junction's
/// block.
void add_junction_pair(ContactSet& c, const PairContext& context, const FaultFace& face, std::size_t k,
                       std::pair<double, const NodeMatrix&> gap_frame)
{
  const auto [junction, row] = context.junctions.of_pair.at({face.name, k});
  const std::int32_t first = c.dim * context.nodes.local.at(face.fault.pairs[k][0]);
  if (context.junctions.pairs[junction].front() == std::make_pair(face.name, k))
    add_junction_block(c, context.domain, context.nodes, context.junctions, junction);
  push_constraint(c, face, k, first + row, gap_frame, false);
  c.junction_nodes.back() = {context.nodes.global.at(face.fault.pairs[k][0]),
                             context.nodes.global.at(face.fault.pairs[k][1])};
}

/// The constraint of one node pair, if this rank owns its + node.
void add_pair(ContactSet& c, const PairContext& context, const FaultFace& face, std::size_t k, std::string& error)
{
  const int d = c.dim, bs = d;
  const std::array<std::int64_t, 2>& pair = face.fault.pairs[k];
  const std::array<double, 3>& n = face.fault.normals[k];
  const FaultNodes& nodes = context.nodes;
  const auto plus = nodes.local.find(pair[0]);
  if (plus == nodes.local.end() or face.output_dof.count(bs * plus->second) == 0) // not owned here
    return;
  const std::int32_t first = bs * plus->second;
  const double* x = &context.coordinates[3 * plus->second];
  const double g = face.spec.gap(x, 0.0);
  const std::string key = context.file + ": fault." + face.name;
  if (const std::string problem = nonnegative_problem(g); !problem.empty() and error.empty())
    error = key + ".gap: " + problem + " at " + point_text(x, d);
  // The pair's change of variables (jump, - face) would leave the + node's
  // foundation constraint no DOF of its own.
  if (context.on_foundation.count(plus->second) and error.empty())
    error = key + ": at " + point_text(x, d)
            + " it reaches a contact boundary, where a fault is not supported yet (end it inside the body)";
  const std::array<double, 3> nu{-n[0], -n[1], -n[2]};
  std::array<bool, 3> held{false, false, false};
  for (int i = 0; i < d; ++i)
    held[i] = context.prescribed[first + i];
  const auto R = node_change_of_variables({nu}, d, held);
  if (!R)
  {
    if (error.empty())
      error = key + ".normal: at " + point_text(x, d)
              + " the fault is not perpendicular to a prescribed displacement component of the node";
    return;
  }
  if (context.junctions.of_pair.count({face.name, k}))
  {
    if (error.empty())
      add_junction_pair(c, context, face, k, {g, *R});
    return;
  }
  ContactBlock block{{}, pair_change_of_variables(*R, d)};
  for (const std::int64_t node : {nodes.global.at(pair[0]), nodes.global.at(pair[1])})
    for (int i = 0; i < d; ++i)
      block.dofs.push_back(bs * node + i);
  c.blocks.push_back(std::move(block));
  // A pair with a prescribed component is held there: frictionless.
  push_constraint(c, face, k, first, {g, *R},
                  !frictionless(c.laws[face.boundary]) and !held[0] and !held[1] and !held[2]);
}

/// The first problem of the junctions on this rank: one that cannot be
/// posed (junction_problem), or a prescribed displacement at a node of
/// one, which its block would mix with the free ones.
std::string junctions_problem(const PairContext& context)
{
  const Junctions& j = context.junctions;
  const int d = context.domain.dim();
  for (std::size_t i = 0; i < j.nodes.size(); ++i)
    for (const std::int64_t v : j.nodes[i])
    {
      const auto node = context.nodes.local.find(v);
      if (node == context.nodes.local.end())
        continue;
      const std::string& fault = j.pairs[i].front().first;
      const auto other = std::find_if(j.pairs[i].begin(), j.pairs[i].end(), [&](const auto& p) { return p.first != fault; });
      const std::string where = context.file + ": fault." + fault + ": at "
                                + point_text(&context.coordinates[3 * node->second], d) + " it meets fault "
                                + other->first + ": ";
      if (const std::string problem = junction_problem(context.domain, j, i); !problem.empty())
        return where + problem;
      for (int r = 0; r < d; ++r)
        if (context.prescribed[d * node->second + r])
          return where + "a displacement is prescribed there, which the contact where faults meet does not "
                         "support yet (end the faults inside the body)";
    }
  return {};
}
} // namespace

void add_fault_pairs(const Scene& scene, const Domain& domain, const CompiledForms& forms,
                     std::shared_ptr<const fem::FunctionSpace> V, ContactSet& c, std::string& error)
{
  if (domain.faults.empty())
    return;
  const PairContext context{scene.file,         domain,
                            V->tabulate_dof_coordinates(false), prescribed_dofs(scene, domain, *V),
                            fault_nodes(domain, *V), foundation_nodes(c), fault_junctions(domain)};
  const int d = domain.dim();
  if (const std::string problem = junctions_problem(context); !problem.empty() and error.empty())
    error = problem;
  for (const auto& around : context.junctions.nodes)
    for (const std::int64_t v : around)
      c.all_junction_nodes.push_back(context.nodes.global.at(v));
  const std::int32_t owned = d * V->dofmap()->index_map->size_local();
  for (const auto& [name, fault] : domain.faults)
  {
    FaultFace face{name, fault, static_cast<int>(c.boundaries.size()), scene.faults.at(name),
                   lumped_measure(domain, forms, V, fault.plus_facets), {}};
    c.boundaries.push_back(name);
    c.faults.push_back(1);
    c.laws.push_back(contact_law(scene.faults.at(name).friction));
    auto [dofs, collapsed] = fem::locate_dofs_topological({*V->sub({0}), *c.output_space}, d - 1, fault.plus_facets);
    for (std::size_t k = 0; k < dofs.size(); ++k)
      if (dofs[k] < owned)
        face.output_dof[dofs[k]] = collapsed[k];
    for (std::size_t k = 0; k < fault.pairs.size(); ++k)
      add_pair(c, context, face, k, error);
  }
}

} // namespace biotcontact
