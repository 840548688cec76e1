#include "contact/junction.h"

#include "contact/change_of_variables.h"

#include <algorithm>
#include <cmath>
#include <mpi.h>
#include <set>

namespace biotcontact
{

namespace
{
/// The representative of node v in a union-find forest.
std::int64_t root(std::map<std::int64_t, std::int64_t>& parent, std::int64_t v)
{
  while (parent.at(v) != v)
    v = parent[v] = parent.at(parent.at(v));
  return v;
}

/// The pairs of every connected piece of the pairs' graph, by its root.
std::map<std::int64_t, std::vector<std::pair<std::string, std::size_t>>> connected_pairs(const Domain& domain)
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
  return by_root;
}

/// Each junction's prescribed flags, from the ranks that hold its nodes.
void gather_prescribed(Junctions& j, const FaultNodes& nodes, std::span<const char> prescribed, int d,
                       MPI_Comm comm)
{
  std::vector<int> flags;
  for (const auto& around : j.nodes)
    for (const std::int64_t v : around)
      for (int i = 0; i < d; ++i)
      {
        const auto node = nodes.local.find(v);
        flags.push_back(node != nodes.local.end() and prescribed[d * node->second + i]);
      }
  MPI_Allreduce(MPI_IN_PLACE, flags.data(), static_cast<int>(flags.size()), MPI_INT, MPI_MAX, comm);
  std::size_t next = 0;
  for (const auto& around : j.nodes)
  {
    j.prescribed.emplace_back(flags.begin() + next, flags.begin() + next + d * around.size());
    next += d * around.size();
  }
}

/// Each pair's row: the next free component of its + node not prescribed.
void assign_rows(Junctions& j, const Domain& domain, int d)
{
  for (std::size_t i = 0; i < j.nodes.size(); ++i)
  {
    std::vector<char> taken = j.prescribed[i];
    for (const auto& [name, k] : j.pairs[i])
    {
      const auto& around = j.nodes[i];
      const auto plus = std::lower_bound(around.begin(), around.end(), domain.faults.at(name).pairs[k][0]);
      const int first = d * static_cast<int>(plus - around.begin());
      int row = 0;
      while (row < d and taken[first + row])
        ++row;
      if (row < d)
        taken[first + row] = 1;
      j.of_pair[{name, k}] = {i, row};
    }
  }
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
} // namespace

Junctions fault_junctions(const Domain& domain, const FaultNodes& nodes, std::span<const char> prescribed)
{
  Junctions j;
  for (const auto& [r, pairs] : connected_pairs(domain))
    if (pairs.size() > 1)
    {
      std::set<std::int64_t> around;
      for (const auto& [name, k] : pairs)
        around.insert(domain.faults.at(name).pairs[k].begin(), domain.faults.at(name).pairs[k].end());
      j.nodes.emplace_back(around.begin(), around.end());
      j.pairs.push_back(pairs);
    }
  gather_prescribed(j, nodes, prescribed, domain.dim(), domain.mesh->comm());
  assign_rows(j, domain, domain.dim());
  return j;
}

std::string junction_problem(const Domain& domain, const Junctions& j, std::size_t i)
{
  const std::vector<JunctionPair> pairs = junction_pairs(domain, j, i);
  const int d = domain.dim();
  for (const JunctionPair& p : pairs)
    for (int c = 0; c < d; ++c)
      if (std::abs(p.normal[c]) > 1e-12 and (j.prescribed[i][d * p.plus + c] or j.prescribed[i][d * p.minus + c]))
        return "a displacement component prescribed there is not perpendicular to the faults, which their contact "
               "would mix with a free one (end the faults inside the body, or hold only components along them)";
  for (const JunctionPair& p : pairs)
    if (p.row >= d)
      return "a piece between the faults is on the + side of more of their faces than it has free displacement "
             "components (orient the faults by their normals so that no piece is)";
  if (!junction_change_of_variables(pairs, static_cast<int>(j.nodes[i].size()), d, j.prescribed[i]))
    return "the faults' faces there are parallel, so their contact constraints are not independent";
  return {};
}

ContactBlock junction_block(const Domain& domain, const FaultNodes& nodes, const Junctions& j, std::size_t i)
{
  const int d = domain.dim();
  ContactBlock block{
      {}, *junction_change_of_variables(junction_pairs(domain, j, i), static_cast<int>(j.nodes[i].size()), d,
                                        j.prescribed[i])};
  for (const std::int64_t v : j.nodes[i])
    for (int c = 0; c < d; ++c)
      block.dofs.push_back(d * nodes.global.at(v) + c);
  return block;
}

} // namespace biotcontact
