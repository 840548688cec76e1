// Scene -> Domain (domain/create_domain.h).
#include "domain/create_domain.h"

#include "domain/gmsh_mesh.h"
#include "domain/working_ranks.h"

#include <dolfinx/mesh/generation.h>
#include <dolfinx/mesh/utils.h>
#include <xtensor/xtensor.hpp>
#include <xtensor/xview.hpp>

namespace biotcontact
{
using namespace dolfinx;

namespace
{

/// The faces of an axis-aligned box: (axis, lower side?) per boundary name.
std::map<std::string, std::pair<int, bool>> box_faces(int d)
{
  if (d == 2)
    return {{"left", {0, true}}, {"right", {0, false}}, {"bottom", {1, true}}, {"top", {1, false}}};
  return {{"left", {0, true}},   {"right", {0, false}}, {"front", {1, true}},
          {"back", {1, false}},  {"bottom", {2, true}}, {"top", {2, false}}};
}
} // namespace

Domain create_domain(const Scene& scene, MPI_Comm world)
{
  const MeshSpec& m = scene.mesh;
  if (m.type == MeshType::gmsh)
    return read_gmsh(scene, world);

  Domain domain;
  MPI_Comm comm = working_communicator(world, built_in_cells(m), scene.solver.cells_per_rank);
  if (comm == MPI_COMM_NULL)
    return domain; // this rank waits
  if (m.type == MeshType::rectangle)
  {
    domain.mesh = std::make_shared<mesh::Mesh>(mesh::create_rectangle(
        comm, {{{m.lower[0], m.lower[1]}, {m.upper[0], m.upper[1]}}}, {m.cells[0], m.cells[1]},
        mesh::CellType::triangle, mesh::GhostMode::shared_facet, mesh::DiagonalType::crossed));
  }
  else
  {
    domain.mesh = std::make_shared<mesh::Mesh>(mesh::create_box(
        comm, {{{m.lower[0], m.lower[1], m.lower[2]}, {m.upper[0], m.upper[1], m.upper[2]}}},
        {m.cells[0], m.cells[1], m.cells[2]}, mesh::CellType::tetrahedron,
        mesh::GhostMode::shared_facet));
  }

  const int d = m.dimension;
  const int fdim = d - 1;
  domain.mesh->topology_mutable().create_connectivity(fdim, d);
  for (const auto& [name, face] : box_faces(d))
  {
    const auto [axis, lower] = face;
    const double value = lower ? m.lower[axis] : m.upper[axis];
    const double tol = 1e-10 * (m.upper[axis] - m.lower[axis]);
    domain.boundaries[name] = mesh::locate_entities_boundary(
        *domain.mesh, fdim,
        [axis = axis, value, tol](const xt::xtensor<double, 2>& x) -> xt::xtensor<bool, 1>
        { return xt::abs(xt::row(x, axis) - value) < tol; });
  }
  domain.regions = locate_regions(scene, *domain.mesh, {});
  MPI_Comm_free(&comm); // the mesh holds its own duplicate
  return domain;
}

} // namespace biotcontact
