// Where faults cross or end on one another (theory.md, "Faults where they
// meet"): the pairs around the point (a line in 3D) form a cycle, their
// jumps summing to zero, so they share one block of the change of variables
// over all the pieces' nodes, each pair's normal jump nu.[u] in a row of its
// own (junction_change_of_variables). A junction is a connected piece of the
// graph whose edges are every fault's node pairs, when it holds more than
// one pair.
#pragma once

#include "assembly/fault_aperture.h"
#include "contact/contact_set.h"

#include <map>
#include <span>
#include <string>
#include <vector>

namespace biotcontact
{

/// @brief The faults' junctions: each one's nodes (input indices, one per
/// piece around it, sorted), its pairs (fault, pair index), which of its
/// nodes' displacement components are prescribed (node by node, d each),
/// and of each pair at a junction its junction and the row of its + node
/// that carries its constraint (the next free component of that node that
/// is not prescribed, in the faults' order; d when none is left).
struct Junctions
{
  std::vector<std::vector<std::int64_t>> nodes;
  std::vector<std::vector<std::pair<std::string, std::size_t>>> pairs;
  std::vector<std::vector<char>> prescribed;
  std::map<std::pair<std::string, std::size_t>, std::pair<std::size_t, int>> of_pair; // -> (junction, row)
};

/// The junctions of the domain's faults; `prescribed` flags the local DOFs
/// of V (ghosts too) that a displacement condition prescribes (collective).
Junctions fault_junctions(const Domain& domain, const FaultNodes& nodes, std::span<const char> prescribed);

/// What makes junction i impossible to pose, empty when nothing does: a
/// piece on the + side of more faces than it has free components, a face
/// not perpendicular to a prescribed component of its nodes, or faces
/// meeting parallel (constraints that are not independent).
std::string junction_problem(const Domain& domain, const Junctions& junctions, std::size_t i);

/// The block of T at junction i in V's numbering (junction_problem empty).
ContactBlock junction_block(const Domain& domain, const FaultNodes& nodes, const Junctions& junctions,
                            std::size_t i);

} // namespace biotcontact
