// The coordinates of the nodes of a P1 space, read from the mesh geometry.
//
// dolfinx's FunctionSpace::tabulate_dof_coordinates pushes the element's
// reference points forward, x = sum_k phi_k(X) x_k, with basis values that
// are zero or one only to round-off: under an optimised BLAS a node at
// x = 0 comes out at 5e-18, and an expression such as sqrt(x) or a normal
// ['0', '-x'] is evaluated off the node. A P1 node is a mesh node, so its
// coordinates are copied from the geometry, exact whatever the BLAS.
#pragma once

#include <dolfinx/fem/FunctionSpace.h>
#include <vector>

namespace biotcontact
{

/// @brief Whether V is P1 on the mesh's nodes: as many nodes per cell as
/// the cell has geometry nodes (an affine mesh's vertices).
bool on_mesh_nodes(const dolfinx::fem::FunctionSpace& V);

/// @brief The coordinates of the nodes (blocks) of the P1 space V, owned
/// and ghost, three per node (z = 0 in 2D), in V's node numbering: the
/// layout of V.tabulate_dof_coordinates(false). Throws if V has not one
/// node per geometry node of each cell.
std::vector<double> node_coordinates(const dolfinx::fem::FunctionSpace& V);

} // namespace biotcontact
