#include "contact/foundation_pair.h"

#include "assembly/node_coordinates.h"

#include <algorithm>
#include <cmath>
#include <dolfinx/fem/DirichletBC.h>
#include <dolfinx/fem/FunctionSpace.h>
#include <map>
#include <optional>
#include <set>

namespace biotcontact
{
using namespace dolfinx;

namespace
{
/// A constraint of one contact boundary at one node, before the nodes on
/// several boundaries are merged.
struct Candidate
{
  std::array<double, 3> normal;
  double gap, lumped;
  std::int32_t output_dof;
  int boundary; // in ContactSet::boundaries
};

/// The normal of a foundation at x, normalised; nothing where it is zero
/// or not finite.
std::optional<std::array<double, 3>> unit_normal(const ContactSpec& contact, const double* x, int d)
{
  std::array<double, 3> n{0, 0, 0};
  double length = 0;
  for (int i = 0; i < d; ++i)
  {
    n[i] = contact.normal[i](x, 0.0);
    length += n[i] * n[i];
  }
  length = std::sqrt(length);
  if (!(length > 0) or !std::isfinite(length))
    return std::nullopt;
  for (int i = 0; i < d; ++i)
    n[i] /= length;
  return n;
}
} // namespace
namespace
{
/// The candidates of each owned node of the contact boundaries, nodes in
/// the order first met (boundaries in the scene's order, each boundary's
/// DOFs in dolfinx's), which is the order of the constraints.
using NodeCandidates = std::vector<std::pair<std::int32_t, std::vector<Candidate>>>;

NodeCandidates gather_candidates(const Scene& scene, const Domain& domain, const CompiledForms& forms,
                                 std::shared_ptr<const fem::FunctionSpace> V, ContactSet& c,
                                 std::string& error)
{
  const int d = domain.dim(), bs = V->dofmap()->index_map_bs();
  const std::int32_t owned = bs * V->dofmap()->index_map->size_local();
  const std::vector<double> coords = node_coordinates(*V);
  auto V0 = V->sub({0});
  NodeCandidates nodes;
  std::map<std::int32_t, std::size_t> position;
  for (const auto& [name, b] : scene.boundaries)
  {
    if (!b.contact)
      continue;
    const int boundary = static_cast<int>(c.boundaries.size());
    c.boundaries.push_back(name);
    c.faults.push_back(0);
    c.laws.push_back(contact_law(b.contact->friction));
    const auto& facets = domain.boundaries.at(name);
    const la::Vector<double> lumped = lumped_measure(domain, forms, V, facets);
    auto [dofs, collapsed] = fem::locate_dofs_topological({*V0, *c.output_space}, d - 1, facets);
    for (std::size_t k = 0; k < dofs.size(); ++k)
    {
      if (dofs[k] >= owned)
        continue;
      const double* x = &coords[3 * (dofs[k] / bs)];
      const double g = b.contact->gap(x, 0.0);
      const auto n = unit_normal(*b.contact, x, d);
      if (const std::string problem = nonnegative_problem(g); !problem.empty() and error.empty())
        error = scene.file + ": boundary." + name + ".contact.gap: " + problem + " at " + point_text(x, d);
      if (!n and error.empty())
        error = scene.file + ": boundary." + name + ".contact.normal: zero or not finite at " + point_text(x, d);
      if (!n)
        continue;
      auto [it, added] = position.emplace(dofs[k], nodes.size());
      if (added)
        nodes.emplace_back(dofs[k], std::vector<Candidate>{});
      nodes[it->second].second.push_back({*n, g, lumped.array()[dofs[k]], collapsed[k], boundary});
    }
  }
  return nodes;
}

/// @brief Where a node's first bad input goes: its scene file (for the
/// key) and the error text, kept if already set.
struct NodeError
{
  const std::string& file;
  std::string* error;
};

/// @brief A contact node: its first DOF in V, its candidate constraints
/// (one per foundation that holds it) and its coordinates.
struct ContactNode
{
  std::int32_t first;
  std::vector<Candidate> candidates;
  const double* x;
};

/// Whether friction acts at a node with the merged candidates `merged`.
/// Friction acts on the tangential components of a node's change of
/// variables (rows 1..d-1 of T): a frictional node always has one, and only
/// one foundation (two would leave fewer tangents than friction needs: the
/// first bad input, naming the frictional boundary, goes into the error). A
/// node with a prescribed component (on a symmetry plane, say) is held there
/// by it: its contact stays frictionless (docs/user-guide.md).
bool frictional_node(const ContactSet& c, const ContactNode& node, const std::vector<Candidate>& merged,
                     const std::vector<char>& prescribed, const NodeError& report)
{
  for (int i = 0; i < c.dim; ++i)
    if (prescribed[node.first + i])
      return false;
  const auto law = std::find_if(merged.begin(), merged.end(),
                                [&](const Candidate& k) { return !frictionless(c.laws[k.boundary]); });
  if (law == merged.end())
    return false;
  if (merged.size() > 1 and report.error->empty())
    *report.error = report.file + ": boundary." + c.boundaries[law->boundary] + ".contact.friction: at "
                    + point_text(node.x, c.dim) + " two foundations meet, where friction is not supported yet";
  return true;
}

/// One node's candidates merged (the same normal from two boundaries: one
/// constraint, the smaller gap, the measures added) and entered into c as
/// bounds on its own components (normals along coordinate axes) or on the
/// components of its change of variables. The first bad input goes into
/// `error`, with its key in `file`.
void add_node(ContactSet& c, const ContactNode& node, const std::vector<char>& prescribed, const std::string& file,
              std::string& error)
{
  const std::int32_t first = node.first;
  const double* x = node.x;
  std::vector<Candidate> merged;
  for (const Candidate& k : node.candidates)
  {
    auto same = std::find_if(merged.begin(), merged.end(),
                             [&](const Candidate& m)
                             {
                               double diff = 0;
                               for (int i = 0; i < 3; ++i)
                                 diff = std::max(diff, std::abs(m.normal[i] - k.normal[i]));
                               return diff < 1e-12;
                             });
    if (same == merged.end())
      merged.push_back(k);
    else
    {
      same->gap = std::min(same->gap, k.gap);
      same->lumped += k.lumped;
    }
  }
  const int d = c.dim;
  std::vector<std::optional<std::pair<int, int>>> axes;
  std::set<int> distinct;
  for (const Candidate& k : merged)
  {
    axes.push_back(coordinate_axis(k.normal, d));
    if (axes.back())
      distinct.insert(axes.back()->first);
  }
  const bool frictional = frictional_node(c, node, merged, prescribed, {file, &error});
  const bool on_axes = !frictional and distinct.size() == merged.size()
                       and std::all_of(axes.begin(), axes.end(), [](const auto& a) { return a.has_value(); });
  std::optional<NodeMatrix> T;
  if (!on_axes)
  {
    std::vector<std::array<double, 3>> normals;
    for (const Candidate& k : merged)
      normals.push_back(k.normal);
    std::array<bool, 3> held{false, false, false};
    for (int i = 0; i < d; ++i)
      held[i] = prescribed[first + i];
    T = node_change_of_variables(normals, d, {false, false, false});
    const std::string key
        = file + ": boundary." + c.boundaries[merged.front().boundary] + ".contact.normal: at " + point_text(x, d);
    if (!T and error.empty())
      error = key + " the normals of the foundations that meet there are not independent";
    else if (T and !node_change_of_variables(normals, d, held) and error.empty())
      error = key + " the normal is not perpendicular to a prescribed displacement component of the node";
    if (!T)
      return;
    ContactBlock block{{}, node_block(*T, d)};
    for (int i = 0; i < d; ++i)
      block.dofs.push_back(c.dof_offset + first + i);
    c.blocks.push_back(std::move(block));
  }
  for (std::size_t j = 0; j < merged.size(); ++j)
  {
    c.dofs.push_back(first + (on_axes ? axes[j]->first : static_cast<int>(j)));
    c.sign.push_back(on_axes ? axes[j]->second : 1);
    c.gap.push_back(merged[j].gap);
    c.lumped.push_back(merged[j].lumped);
    c.normal.push_back(merged[j].normal);
    c.boundary.push_back(merged[j].boundary);
    c.pair_node.push_back(-1);
    c.junction_nodes.push_back({-1, -1});
    c.pair_frame.push_back(T.value_or(NodeMatrix{}));
    c.frictional.push_back(frictional);
    c.output_dofs.push_back(merged[j].output_dof);
  }
}
} // namespace

void add_foundation_pairs(const Scene& scene, const Domain& domain, const CompiledForms& forms,
                          std::shared_ptr<const fem::FunctionSpace> V, ContactSet& c, std::string& error)
{
  NodeCandidates nodes = gather_candidates(scene, domain, forms, V, c, error);
  const std::vector<char> prescribed = prescribed_dofs(scene, domain, *V);
  const std::vector<double> coords = node_coordinates(*V);
  const int bs = V->dofmap()->index_map_bs();
  for (auto& [first, candidates] : nodes)
    add_node(c, {first, std::move(candidates), &coords[3 * (first / bs)]}, prescribed, scene.file, error);
}

} // namespace biotcontact
