// The coordinates of the nodes of a P1 space, from the mesh geometry.
#include "assembly/node_coordinates.h"

#include <algorithm>
#include <dolfinx/common/IndexMap.h>
#include <dolfinx/fem/DofMap.h>
#include <dolfinx/mesh/Mesh.h>
#include <stdexcept>

namespace biotcontact
{
using namespace dolfinx;

bool on_mesh_nodes(const fem::FunctionSpace& V)
{
  const auto& cell_nodes = V.mesh()->geometry().dofmap();
  return cell_nodes.num_nodes() == 0
         or V.dofmap()->cell_dofs(0).size() == cell_nodes.links(0).size();
}

std::vector<double> node_coordinates(const fem::FunctionSpace& V)
{
  const mesh::Mesh& mesh = *V.mesh();
  const mesh::Geometry& geometry = mesh.geometry();
  const auto& cell_nodes = geometry.dofmap();
  const std::span<const double> x = geometry.x();
  const fem::DofMap& dofmap = *V.dofmap();
  const auto& nodes = *dofmap.index_map;
  std::vector<double> coordinates(3 * (nodes.size_local() + nodes.num_ghosts()));
  // The cell's DOFs and geometry nodes share basix's P1 order: vertex i of
  // the reference cell is the i-th of each.
  for (std::int32_t c = 0; c < cell_nodes.num_nodes(); ++c)
  {
    const auto dofs = dofmap.cell_dofs(c);
    const auto geometry_nodes = cell_nodes.links(c);
    if (dofs.size() != geometry_nodes.size())
      throw std::logic_error("node_coordinates: the space is not P1 on the mesh's nodes");
    for (std::size_t i = 0; i < dofs.size(); ++i)
      std::copy_n(x.data() + 3 * geometry_nodes[i], 3, coordinates.data() + 3 * dofs[i]);
  }
  return coordinates;
}

} // namespace biotcontact
