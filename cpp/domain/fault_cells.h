// The cells of a fault's own flow: each facet of the fault that the split
// opened is one cell of the fault (a segment in 2D, a triangle in 3D), where
// the fault's pressure p_f is one unknown. Two cells meet at an edge (a node
// in 2D, an edge of two nodes in 3D); an edge of one cell only is an end of
// the fault: on the outer boundary (its group given) or a tip inside the
// rock. Computed on rank 0 from the split mesh (domain/faults.h), the same
// on every rank afterwards. The prototype's twin is
// python_prototype/domain/fault_cells.py.
#pragma once

#include "domain/faults.h"
#include "scene/scene.h"

#include <array>
#include <cstdint>
#include <mpi.h>
#include <string>
#include <vector>

namespace biotcontact
{

/// @brief Edges of a fault's cells: links (the two cells that share the
/// edge) or ends (the one cell of an edge on the outer boundary). Distances
/// run from each cell's centroid to the edge's midpoint (the two-point
/// flux, docs/theory.md "Flow in a fault"); an edge's measure is 1 in 2D
/// (per metre of thickness).
struct FaultEdges
{
  explicit FaultEdges(int width) : width(width) {}

  int width;                           // cells per edge: 2 for links, 1 for ends
  std::vector<std::int64_t> cells;     // width per edge
  std::vector<double> measures;        // per edge
  std::vector<double> distances;       // width per edge
  std::vector<std::array<double, 3>> points; // midpoints

  std::size_t size() const { return measures.size(); }
};

/// @brief A fault's cells, the links between them and its ends on the outer
/// boundary (each with its boundary group's name).
struct FaultCells
{
  std::vector<std::int64_t> keys; // d per cell: the + face's nodes, sorted (the split numbering)
  std::vector<std::int64_t> twins; // d per cell: each key's node on the - face (itself at a tip)
  std::vector<std::array<double, 3>> normals; // per cell: the unit normal into the + side
  std::vector<double> measures;   // length or area per cell
  std::vector<std::array<double, 3>> centroids;
  std::vector<std::array<double, 3>> vertices; // d per cell: the + face's nodes, in the order of keys
  FaultEdges links{2}, ends{1};
  std::vector<std::string> end_groups;
  // one-cell edges inside the body: a tip, or an edge where the split
  // separated the fault's cells at another fault (fault_network)
  FaultEdges inner{1};
  // the links the split cut where another fault crosses or ends on this
  // one (two inner edges at one point): one plane to its mechanics
  FaultEdges cut{2};

  std::size_t size() const { return measures.size(); }
};

/// @brief Where faults' cells meet at one edge other than as one fault's
/// link: where faults cross or one ends on another (an intersection in the
/// fault network). Its members are every cell with an edge there.
struct FaultJunction
{
  std::array<double, 3> point;     // the edge's midpoint
  double measure;                  // the edge's length in 3D, 1 in 2D
  std::vector<std::size_t> faults; // per member: its fault (an index into the faults given)
  std::vector<std::int64_t> cells; // per member: its cell in that fault
  std::vector<double> distances;   // per member: from its centroid to the point
};

/// @brief A network of faults: each fault's links but those at junctions,
/// and the junctions.
struct FaultNetwork
{
  std::vector<FaultEdges> links; // per fault
  std::vector<FaultJunction> junctions;
};

/// The network of `faults`, the faults whose cells exchange fluid: a point
/// where more than one of their edges (links and inner edges, matched by
/// their midpoints, which the split's copies of a node reproduce exactly)
/// meet is a junction of all their cells, and its links leave the faults'
/// links (docs/theory.md, "Flow in a fault network").
FaultNetwork fault_network(const std::vector<const FaultCells*>& faults);

/// The cells of the fault `split` in the split mesh `mesh`.
FaultCells fault_cells(const InputMesh& mesh, const SplitFault& split);

/// @brief The fault cells a well meets and the share of its rate each takes.
struct WellOnFault
{
  std::vector<std::int64_t> cells;
  std::vector<double> shares;
};

/// The fault cells well `w` meets (equal shares where it meets several, at a
/// shared node or edge): in 2D the cells within 1e-6 of their length of
/// the well's point, in 3D the triangles its vertical segment crosses;
/// empty when it meets none.
WellOnFault well_cells(const FaultCells& cells, const WellSpec& w);

/// Rank 0's `cells` on every rank (collective).
void share_fault_cells(FaultCells& cells, MPI_Comm comm);

} // namespace biotcontact
