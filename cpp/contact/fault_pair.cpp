#include "contact/fault_pair.h"

#include "assembly/fault_aperture.h"
#include "assembly/linear_algebra.h"
#include "assembly/node_coordinates.h"
#include "contact/junction.h"

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
    c.blocks.push_back(junction_block(context.domain, context.nodes, context.junctions, junction));
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

/// The first problem of the junctions at a node this rank holds
/// (junction_problem), naming two of the faults and the point.
std::string junctions_problem(const PairContext& context)
{
  const Junctions& j = context.junctions;
  for (std::size_t i = 0; i < j.nodes.size(); ++i)
  {
    const std::string problem = junction_problem(context.domain, j, i);
    const auto node = std::find_if(j.nodes[i].begin(), j.nodes[i].end(),
                                   [&](std::int64_t v) { return context.nodes.local.count(v) > 0; });
    if (problem.empty() or node == j.nodes[i].end())
      continue;
    const std::string& fault = j.pairs[i].front().first;
    const auto other = std::find_if(j.pairs[i].begin(), j.pairs[i].end(), [&](const auto& p) { return p.first != fault; });
    return context.file + ": fault." + fault + ": at "
           + point_text(&context.coordinates[3 * context.nodes.local.at(*node)], context.domain.dim())
           + " it meets fault " + other->first + ": " + problem;
  }
  return {};
}
} // namespace

void add_fault_pairs(const Scene& scene, const Domain& domain, const CompiledForms& forms,
                     std::shared_ptr<const fem::FunctionSpace> V, ContactSet& c, std::string& error)
{
  if (domain.faults.empty())
    return;
  FaultNodes nodes = fault_nodes(domain, *V);
  std::vector<char> prescribed = prescribed_dofs(scene, domain, *V);
  Junctions junctions = fault_junctions(domain, nodes, prescribed);
  const PairContext context{scene.file,
                            domain,
                            node_coordinates(*V),
                            std::move(prescribed),
                            std::move(nodes),
                            foundation_nodes(c),
                            std::move(junctions)};
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
