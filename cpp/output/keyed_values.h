// The unknowns of a field under names that no partition changes: each DOF
// named by the input indices of the mesh entity it sits on, so that a
// checkpoint written on one partition restores on any other
// (output/checkpoint.h); and a signature of the mesh, so that a checkpoint
// of another mesh is refused.
#pragma once

#include "assembly/linear_algebra.h"

#include <cstdint>
#include <dolfinx/mesh/Mesh.h>
#include <span>
#include <string>
#include <vector>

namespace biotcontact
{

/// @brief The owned entries of one field, each under a name that no
/// partition changes.
///
/// A DOF is named by the mesh entity it sits on, written as the input
/// indices of the entity's vertices in ascending order (a vertex: its input
/// index times the block size plus the component; a facet: its d vertices;
/// a cell: its input cell index). A flux DOF is the flux through its facet
/// along the normal of that vertex order; dolfinx orients a facet by the
/// partition's global vertex numbering, so the value is turned by the
/// parity of the permutation between the two orders.
struct KeyedValues
{
  int width = 1;                  // int64 per name
  std::vector<std::int64_t> keys; // width per entry
  std::vector<double> values;
};

/// The owned entries of `part` in `unknowns` with their names.
KeyedValues keyed_values(const dolfinx::mesh::Mesh& mesh, const UnknownsPart& part,
                         std::span<const double> unknowns);

/// Sets the owned entries of `part` in `unknowns` from the stored `values`
/// (every rank's, or this rank's own), then the ghost entries from their
/// owners; returns how many owned ones were not found (collective).
std::int64_t restore_values(const dolfinx::mesh::Mesh& mesh, const UnknownsPart& part, const KeyedValues& values,
                            std::span<double> unknowns);

/// A partition-independent signature of the mesh: its global numbers of
/// nodes and cells and a weighted sum of the node coordinates by input
/// index. A checkpoint keeps it, so that a mesh whose nodes moved or whose
/// size changed under the same scene text is refused (collective).
std::vector<double> mesh_signature(const dolfinx::mesh::Mesh& mesh);

/// How the mesh of signature `current` differs from the `stored` one, in
/// words; empty when they are the same (counts equal, the sums to
/// round-off: ranks add in another order).
std::string mesh_difference(const std::vector<double>& stored, const std::vector<double>& current);

} // namespace biotcontact
