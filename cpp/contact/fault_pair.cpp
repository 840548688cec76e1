#include "contact/fault_pair.h"

#include "assembly/fault_aperture.h"
#include "assembly/linear_algebra.h"

#include <dolfinx/fem/DirichletBC.h>
#include <dolfinx/fem/FunctionSpace.h>
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
/// fault nodes are, and the nodes (local) that a foundation's constraint
/// holds.
struct PairContext
{
  const std::string& file;
  std::vector<double> coordinates;
  std::vector<char> prescribed;
  FaultNodes nodes;
  std::set<std::int32_t> on_foundation;
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
  ContactBlock block{{}, pair_change_of_variables(*R, d)};
  for (const std::int64_t node : {nodes.global.at(pair[0]), nodes.global.at(pair[1])})
    for (int i = 0; i < d; ++i)
      block.dofs.push_back(bs * node + i);
  c.blocks.push_back(std::move(block));
  c.dofs.push_back(first);
  c.sign.push_back(1);
  c.gap.push_back(g);
  c.lumped.push_back(face.lumped.array()[first]);
  c.normal.push_back(n);
  c.boundary.push_back(face.boundary);
  c.pair_node.push_back(pair[0]);
  c.pair_frame.push_back(*R);
  // A pair with a prescribed component is held there: frictionless.
  c.frictional.push_back(!frictionless(c.laws[face.boundary]) and !held[0] and !held[1] and !held[2]);
  c.output_dofs.push_back(face.output_dof.at(first));
}
} // namespace

void add_fault_pairs(const Scene& scene, const Domain& domain, const CompiledForms& forms,
                     std::shared_ptr<const fem::FunctionSpace> V, ContactSet& c, std::string& error)
{
  if (domain.faults.empty())
    return;
  const PairContext context{scene.file, V->tabulate_dof_coordinates(false), prescribed_dofs(scene, domain, *V),
                            fault_nodes(domain, *V), foundation_nodes(c)};
  const int d = domain.dim();
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
