// The opening of the conduit faults' cells as a linear map of the
// displacement, and the load of the faults' fluid pressure on their faces
// (docs/theory.md "Flow in a fault"). Per cell k (a facet of the fault, d
// nodes), the mean of the nodes' openings g0 + [u].n:
//
//     w_k = g0_k + (J u)_k,   (J u)_k = (1/d) sum_i n_k . (u(i+) - u(i-)),
//
// n_k the cell's normal into the + side, i- the twin of node i+ on the -
// face (the node itself at a tip, where the opening is 0). The fluid
// pressure's load is the adjoint b += J^T (|k| p_f) (FaultAperture::add_load).
// The prototype's twin is python_prototype/assembly/fault_aperture.py.
#pragma once

#include "assembly/fault_rows.h"
#include "assembly/linear_algebra.h"
#include "domain/domain.h"
#include "scene/scene.h"

#include <dolfinx/fem/FunctionSpace.h>
#include <dolfinx/la/Vector.h>
#include <map>
#include <petscmat.h>
#include <span>
#include <string>
#include <vector>

namespace biotcontact
{

/// @brief Where the faults' nodes are in a P1 space V: the local node of
/// each input index this rank holds, and the global node of every fault
/// node (a pair's - node may be held by another rank only).
struct FaultNodes
{
  std::map<std::int64_t, std::int32_t> local;
  std::map<std::int64_t, std::int64_t> global;
};

/// The nodes of every fault's node pairs and cells in V (collective).
FaultNodes fault_nodes(const Domain& domain, const dolfinx::fem::FunctionSpace& V);

/// @brief The mean opening w = g0 + J u of each conduit fault cell, and the
/// load J^T (|k| p_f) of the faults' fluid pressure. The rows of J are the
/// conduit cells in ConduitFaults' numbering (fault by fault), each on its
/// owner (fault_rows.h).
class FaultAperture
{
public:
  /// V: the P1 displacement space.
  FaultAperture(const Scene& scene, const Domain& domain, const dolfinx::fem::FunctionSpace& V);
  ~FaultAperture();
  FaultAperture(const FaultAperture&) = delete;
  FaultAperture& operator=(const FaultAperture&) = delete;

  /// The conduit cells' mean openings g0 + J u, every cell on every rank
  /// (collective).
  std::vector<double> opening(dolfinx::la::Vector<double>& u) const;
  /// Per conduit cell the mean of `nodal` (a value per fault and + node
  /// this rank knows, by the fault's name and the node's input index; each
  /// on one rank) over the cell's nodes that have one on its fault, 0 where
  /// none has; every cell on every rank (collective). Of the fault pairs'
  /// contact tractions, the cells' effective normal stress s_n.
  std::vector<double> cell_means(const std::map<std::pair<std::string, std::int64_t>, double>& nodal) const;
  /// Adds J^T (|k| p_f) to b but on the Dirichlet rows of `bcs`; `p_f`:
  /// this rank's entries of the pressures (collective). The fluid
  /// pressure p_f pushes both faces apart; its work on the displacement is
  /// sum_k p_k |k| w_k, so its load is the adjoint of J: for P1 on a flat
  /// face each node takes |k|/d of the face's p_f n, the integral
  /// forms/biot.py's L_face_pressure takes of a given pressure.
  void add_load(std::span<const double> p_f, const BCs& bcs, dolfinx::la::Vector<double>& b) const;
  /// J itself (rows: the conduit cells, each on its owner; columns: V's
  /// DOFs), and the cells' measures |k| (this rank's entries).
  Mat jump() const { return _J; }
  const std::vector<double>& measures() const { return _measures; }

private:
  Mat _J = nullptr;
  Vec _cells = nullptr;                // on J's rows
  std::vector<double> _gap, _measures; // per cell (this rank's entries)
  std::vector<std::int64_t> _keys;     // the + nodes of every cell, d per cell (every rank)
  std::vector<std::int64_t> _fault;    // every cell's fault, its position in the scene's faults (every rank)
  std::map<std::string, std::int64_t> _fault_index; // the scene's faults' positions, by name
  std::int64_t _size = 0;
  MPI_Comm _comm;
  FaultRows _rows;
};

} // namespace biotcontact
