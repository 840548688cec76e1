#include "contact/bonds.h"

#include "assembly/linear_algebra.h"

#include <algorithm>
#include <map>

namespace biotcontact
{
using namespace dolfinx;

namespace
{
/// Whether constraint k's law has a cohesion (the prototype's
/// _cohesive_constraints, per constraint).
bool has_cohesion(const ContactSet& set, std::size_t k) { return set.laws[set.boundary[k]].cohesion > 0; }
} // namespace

std::vector<std::int64_t> constraint_keys(const ContactSet& set)
{
  // The P1 output space: a cell's DOF k sits on its geometry node k.
  const fem::FunctionSpace& P1 = *set.output_space;
  const mesh::Geometry& geometry = P1.mesh()->geometry();
  const std::vector<std::int64_t>& input = geometry.input_global_indices();
  std::vector<std::int64_t> node_input(P1.dofmap()->index_map->size_local()
                                       + P1.dofmap()->index_map->num_ghosts());
  const auto cells = P1.mesh()->topology().index_map(P1.mesh()->topology().dim());
  for (std::int32_t c = 0; c < cells->size_local() + cells->num_ghosts(); ++c)
  {
    auto dofs = P1.dofmap()->cell_dofs(c);
    auto nodes = geometry.dofmap().links(c);
    for (std::size_t k = 0; k < dofs.size(); ++k)
      node_input[dofs[k]] = input[nodes[k]];
  }
  std::vector<std::int64_t> keys;
  std::map<std::int32_t, int> seen; // constraints so far per output DOF
  for (std::int32_t dof : set.output_dofs)
    keys.push_back(4 * node_input[dof] + seen[dof]++);
  return keys;
}

bool cohesive(const ContactSet& set)
{
  return std::any_of(set.laws.begin(), set.laws.end(), [](const ContactLaw& l) { return l.cohesion > 0; });
}

bool break_pulled_bonds(ContactSet& set, std::span<const char> closed, std::size_t first)
{
  bool broke = false;
  std::size_t j = first;
  for (std::size_t k = 0; k < set.dofs.size(); ++k)
  {
    if (!set.frictional[k])
      continue;
    if (set.bonded[k] and has_cohesion(set, k) and j < closed.size() and !closed[j])
      set.bonded[k] = 0, broke = true;
    ++j;
  }
  return broke;
}

bool break_open_bonds(ContactSet& set, std::span<const signed char> closed)
{
  bool broke = false;
  for (std::size_t k = 0; k < set.dofs.size(); ++k)
    if (set.bonded[k] and !closed[k])
      set.bonded[k] = 0, broke = true;
  return broke;
}

std::vector<double> broken_bond_names(const ContactSet& set, std::span<const char> bonded, MPI_Comm comm)
{
  const std::vector<std::int64_t> keys = constraint_keys(set);
  std::vector<std::int64_t> mine;
  for (std::size_t k = 0; k < keys.size(); ++k)
    if (!bonded[k] and has_cohesion(set, k))
      mine.push_back(keys[k]);
  std::vector<double> all;
  for (std::int64_t key : all_gather(mine, comm).values)
    all.push_back(static_cast<double>(key)); // exact below 2^53
  std::sort(all.begin(), all.end());
  return all;
}

std::vector<char> bonds_from_names(const ContactSet& set, const std::vector<double>& broken)
{
  std::vector<char> bonded;
  for (std::int64_t key : constraint_keys(set))
    bonded.push_back(!std::binary_search(broken.begin(), broken.end(), static_cast<double>(key)));
  return bonded;
}

} // namespace biotcontact
