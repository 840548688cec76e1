// The domain of a run: its mesh, the facets of its named boundaries, its
// faults after the split and the material region of each cell, as
// domain/create_domain.h builds it from a scene; the facet markers the
// forms integrate on, and the input index of each vertex. The prototype's
// twin is python_prototype/domain/domain.py.
#pragma once

#include "domain/fault_cells.h"
#include "domain/regions.h"
#include "scene/scene.h"

#include <array>
#include <dolfinx/mesh/Mesh.h>
#include <dolfinx/mesh/MeshTags.h>
#include <map>
#include <memory>
#include <mpi.h>
#include <string>
#include <vector>

namespace biotcontact
{

/// @brief A fault after the mesh was split along it (domain/faults.h): the
/// facets of its two faces, exterior facets of the split mesh (sorted local
/// indices), its node pairs and its cells for the fault's own flow
/// (domain/fault_cells.h), the same on every rank.
struct Fault
{
  std::vector<std::int32_t> plus_facets, minus_facets;
  /// Per node pair: the input indices of its node on the + side and on the
  /// - side (mesh.geometry().input_global_indices()), and the fault's unit
  /// normal there, pointing into the + side (the mean of its facets').
  std::vector<std::array<std::int64_t, 2>> pairs;
  std::vector<std::array<double, 3>> normals;
  FaultCells cells;
};

struct Domain
{
  std::shared_ptr<dolfinx::mesh::Mesh> mesh;
  /// Sorted local indices of the exterior facets of each named boundary.
  std::map<std::string, std::vector<std::int32_t>> boundaries;
  /// The faults ([fault.NAME]), split.
  std::map<std::string, Fault> faults;
  /// The material region of each cell ([region.NAME]).
  CellRegions regions;

  int dim() const { return mesh->topology().dim(); }
  /// Facet tags with the marker of forms/biot.py (1) on one boundary, for
  /// the ds(1) integrals of that boundary.
  std::shared_ptr<const dolfinx::mesh::MeshTags<std::int32_t>> marker(const std::string& name) const;
  /// The same on the facets of several boundaries.
  std::shared_ptr<const dolfinx::mesh::MeshTags<std::int32_t>> marker(const std::vector<std::string>& names) const;
  /// The same on both faces of a fault.
  std::shared_ptr<const dolfinx::mesh::MeshTags<std::int32_t>> fault_faces(const std::string& fault) const;
};

/// The input index of every local vertex (owned and ghost): vertex k of a
/// cell is the cell's geometry node k on a P1 mesh.
std::vector<std::int64_t> vertex_input_indices(const dolfinx::mesh::Mesh& mesh);

/// The facets of the faces loaded by the pore pressure
/// (boundary.NAME.pore_pressure_load, and both faces of a fault with
/// fault.NAME.pore_pressure_load) with the marker of forms/biot.py, for
/// the face term of the pressure load; null when the scene has none.
std::shared_ptr<const dolfinx::mesh::MeshTags<std::int32_t>> pore_pressure_faces(const Scene& scene,
                                                                                 const Domain& domain);

} // namespace biotcontact
