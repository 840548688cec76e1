// Faults: an input simplex mesh split along interior facet groups, on rank 0
// before dolfinx distributes it. Each fault node gets one node per piece of
// the cells around it that the faults separate (two on one fault, the +
// side's a new node at the same point; three or four where faults cross or
// end on one another), so the faces become faces of the mesh that the
// contact can pair; a fault's edges inside the body (its tips) stay shared,
// and so does a facet whose nodes are all tips: its two faces are the same
// nodes. The prototype's twin is python_prototype/domain/faults.py.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace biotcontact
{

/// @brief The input mesh as read on rank 0 (the arrays of a gmsh file that
/// read_gmsh (domain/gmsh_mesh.h) hands to dolfinx).
struct InputMesh
{
  int dim = 2;
  std::vector<double> x;                 // dim coordinates per node
  std::vector<std::int64_t> cells;       // dim+1 node indices per cell
  std::vector<std::int64_t> facets;      // dim node indices per facet of a named group
  std::vector<std::int32_t> facet_group; // per facet, an index into names
  std::vector<std::string> names;
};

/// @brief What is asked: a fault's facet group and its normal hint, a
/// direction the fault's normal is oriented along (n . hint > 0).
struct FaultRequest
{
  std::string name;
  std::array<double, 3> hint{0, 0, 0};
};

/// @brief One fault after the split. Facet k of plus_facets, minus_facets
/// and normals is the fault's k-th facet in input order.
struct SplitFault
{
  std::string name;
  // dim node indices per fault facet in the split numbering: its face on the
  // + side (the side the normal points into), and on the - side.
  std::vector<std::int64_t> plus_facets, minus_facets;
  // per fault facet, the unit normal oriented by the hint, into the + side
  std::vector<std::array<double, 3>> normals;
  // per node pair: (its index on the + side, its index on the - side), in
  // increasing order of the input node they come from
  std::vector<std::pair<std::int64_t, std::int64_t>> pairs;
  // the fault nodes kept shared (the fault's edges inside the body; where
  // another fault splits such a node, each copy on this fault), sorted
  std::vector<std::int64_t> tips;
  // (input node, the other fault's index) where this fault crosses, ends on
  // or is ended on by another, in increasing node order
  std::vector<std::pair<std::int64_t, std::size_t>> meets;
};

/// Splits `mesh` in place along each requested fault and returns the faults
/// in request order. A split node's new copies (one on one fault, two or
/// three where faults cross or end on one another) are appended to x (in
/// increasing order of the input index) and the cells and boundary facets
/// of their pieces are renumbered; the faults' facets leave facets and
/// facet_group (names keeps its entries). Throws SceneError, one line
/// "KEY_PREFIXNAME: ..." (e.g. key_prefix "scene.toml: fault."), for a group
/// that is missing, empty or on the outer boundary, a hint parallel to the
/// fault, a hint that orients the fault inconsistently, a facet in two
/// faults' groups, and one fault that branches or crosses itself.
std::vector<SplitFault> split_along_faults(InputMesh& mesh, const std::vector<FaultRequest>& faults,
                                           const std::string& key_prefix);

} // namespace biotcontact
