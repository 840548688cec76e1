// A gmsh mesh read on rank 0, split along the faults and distributed by
// dolfinx (domain/gmsh_mesh.h).
#include "domain/gmsh_mesh.h"

#include "domain/faults.h"
#include "domain/gmsh_api.h"
#include "domain/mesh_cache.h"
#include "domain/pieces.h"
#include "domain/tip_grading.h"
#include "domain/working_ranks.h"

#include <algorithm>
#include <cmath>
#include <dolfinx/fem/CoordinateElement.h>
#include <dolfinx/io/xdmf_utils.h>
#include <dolfinx/mesh/utils.h>
#include <filesystem>
#include <functional>

namespace biotcontact
{
using namespace dolfinx;

namespace
{

/// What rank 0 reads from a gmsh file: nodes, simplices, and the facets of
/// each named physical group of dimension d-1.
struct GmshData
{
  std::vector<double> x;                 // num_nodes x d
  std::vector<std::int64_t> cells;       // d+1 node indices per cell
  std::vector<std::int64_t> facets;      // d node indices per boundary facet
  std::vector<std::int32_t> facet_group; // index into names
  std::vector<std::string> names;
  /// The region of each cell (input order) from the physical groups of
  /// cells the scene's regions name (regions_of_groups).
  std::vector<std::int32_t> cell_region;
  /// The scene's faults after the split, in the order of scene.faults (their
  /// faces are the last two facet groups each, + then -).
  std::vector<Fault> faults;
};

/// Calls visit(name, element tags, node tags) once for each physical group
/// of dimension `dim` with its elements of gmsh type `type` (an unnamed
/// group is "group<tag>").
void for_each_group(int dim, int type,
                    const std::function<void(const std::string&, const std::vector<std::size_t>&,
                                             const std::vector<std::size_t>&)>& visit)
{
  gmsh::vectorpair groups;
  gmsh::model::getPhysicalGroups(groups, dim);
  for (const auto& [group_dim, tag] : groups)
  {
    std::string name;
    gmsh::model::getPhysicalName(group_dim, tag, name);
    std::vector<int> entities;
    gmsh::model::getEntitiesForPhysicalGroup(group_dim, tag, entities);
    std::vector<std::size_t> element_tags, node_tags;
    for (int entity : entities)
    {
      std::vector<std::size_t> etags, ntags;
      gmsh::model::mesh::getElementsByType(type, etags, ntags, entity);
      element_tags.insert(element_tags.end(), etags.begin(), etags.end());
      node_tags.insert(node_tags.end(), ntags.begin(), ntags.end());
    }
    visit(name.empty() ? "group" + std::to_string(tag) : name, element_tags, node_tags);
  }
}

/// The input indices of the cells of each named physical group of cells.
std::map<std::string, std::vector<std::int64_t>> cell_groups(int d, const std::vector<std::size_t>& element_tags)
{
  std::map<std::size_t, std::int64_t> position;
  for (std::size_t i = 0; i < element_tags.size(); ++i)
    position[element_tags[i]] = static_cast<std::int64_t>(i);
  std::map<std::string, std::vector<std::int64_t>> groups;
  for_each_group(d, d == 2 ? 2 : 4,
                 [&](const std::string& name, const std::vector<std::size_t>& etags, const std::vector<std::size_t>&)
                 {
                   std::vector<std::int64_t>& cells = groups[name];
                   for (std::size_t t : etags)
                     cells.push_back(position.at(t));
                 });
  return groups;
}

/// Keeps only the nodes of the cells, numbered in their order in the file:
/// the mesh's input numbering is then 0 .. N-1, the rows of the output.
void drop_unused_nodes(GmshData& data, int d)
{
  std::vector<std::int64_t> index(data.x.size() / d, -1);
  for (std::int64_t node : data.cells)
    index[node] = 0;
  std::vector<double> x;
  for (std::size_t i = 0, used = 0; i < index.size(); ++i)
    if (index[i] == 0)
    {
      index[i] = static_cast<std::int64_t>(used++);
      x.insert(x.end(), data.x.begin() + i * d, data.x.begin() + (i + 1) * d);
    }
  data.x = std::move(x);
  for (std::int64_t& node : data.cells)
    node = index[node];
  for (std::int64_t& node : data.facets)
    node = index[node];
}

/// Refuses a cell of (nearly) zero area or volume, measured against its
/// longest edge: the stiffness and the mass balance of such a cell are
/// round-off, and a split along a fault cannot tell its sides apart.
void check_cells(const Scene& scene, const GmshData& data)
{
  const int d = scene.mesh.dimension;
  for (std::size_t c = 0; c < data.cells.size() / (d + 1); ++c)
  {
    const std::int64_t* nodes = &data.cells[(d + 1) * c];
    std::array<std::array<double, 3>, 3> edge{};
    double longest = 0;
    for (int k = 0; k < d; ++k)
    {
      for (int i = 0; i < d; ++i)
        edge[k][i] = data.x[d * nodes[k + 1] + i] - data.x[d * nodes[0] + i];
      longest = std::max(longest, std::hypot(edge[k][0], edge[k][1], edge[k][2]));
    }
    const auto& [a, b, e] = edge;
    const double measure = d == 2 ? std::abs(a[0] * b[1] - a[1] * b[0]) / 2
                                  : std::abs(a[0] * (b[1] * e[2] - b[2] * e[1]) - a[1] * (b[0] * e[2] - b[2] * e[0])
                                             + a[2] * (b[0] * e[1] - b[1] * e[0]))
                                        / 6;
    if (measure < 1e-10 * std::pow(longest, d))
      throw SceneError(scene.mesh.file + ": a cell of zero " + (d == 2 ? "area" : "volume") + " at "
                       + point_text(&data.x[d * nodes[0]], d)
                       + ": the mesh is degenerate there (check its sizes; at a crack's tip gmsh 4.8's "
                         "Mesh.RandomFactor = 1e-12 or another Mesh.Algorithm avoids it)");
  }
}

/// Each [fault.NAME] names a physical group of dimension d-1 of the file;
/// throws SceneError naming the key otherwise (gmsh open).
void check_fault_groups(const Scene& scene)
{
  const int d = scene.mesh.dimension;
  gmsh::vectorpair groups;
  gmsh::model::getPhysicalGroups(groups);
  for (const auto& [name, fault] : scene.faults)
  {
    const std::string key = scene.file + ": fault." + name + ": ";
    std::string known;
    int dimension = -1;
    for (const auto& [group_dim, tag] : groups)
    {
      std::string group;
      gmsh::model::getPhysicalName(group_dim, tag, group);
      group = group.empty() ? "group" + std::to_string(tag) : group;
      known += (known.empty() ? "" : ", ") + group;
      if (group == name and (dimension < 0 or group_dim == d - 1))
        dimension = group_dim;
    }
    if (dimension < 0)
      throw SceneError(key + "no physical group " + name + " in " + scene.mesh.file + " (it has "
                       + (known.empty() ? "none" : known) + ")");
    if (dimension != d - 1)
      throw SceneError(key + "the physical group " + name + " is of dimension " + std::to_string(dimension)
                       + "; a fault is of dimension " + std::to_string(d - 1)
                       + (d == 2 ? " (a curve in the surface)" : " (a surface in the volume)"));
  }
}

/// The unit normal at each node pair of a split fault: the mean of the
/// normals of its facets that hold the pair's + node.
std::vector<std::array<double, 3>> pair_normals(const SplitFault& split, int d)
{
  std::map<std::int64_t, std::array<double, 3>> sum;
  for (std::size_t k = 0; k < split.normals.size(); ++k)
    for (int i = 0; i < d; ++i)
      for (int j = 0; j < 3; ++j)
        sum[split.plus_facets[d * k + i]][j] += split.normals[k][j];
  std::vector<std::array<double, 3>> normals;
  for (const auto& [plus, minus] : split.pairs)
  {
    std::array<double, 3> n = sum.at(plus);
    const double length = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    for (double& c : n)
      c /= length;
    normals.push_back(n);
  }
  return normals;
}

/// Splits the mesh along the scene's faults (domain/faults.h): their faces
/// become the last facet groups, + and - of each fault in turn.
void split_faults(const Scene& scene, GmshData& data)
{
  if (scene.faults.empty())
    return;
  const int d = scene.mesh.dimension;
  InputMesh mesh{d, std::move(data.x), std::move(data.cells), std::move(data.facets), std::move(data.facet_group),
                 std::move(data.names)};
  std::vector<FaultRequest> requests;
  for (const auto& [name, fault] : scene.faults)
  {
    FaultRequest r{name, {0, 0, 0}};
    std::copy(fault.normal.begin(), fault.normal.end(), r.hint.begin());
    requests.push_back(r);
  }
  const std::vector<SplitFault> split = split_along_faults(mesh, requests, scene.file + ": fault.");
  refuse_free_pieces(scene, mesh, split);
  std::vector<FaultCells> cells; // before the faces join the facets
  for (const SplitFault& f : split)
    cells.push_back(fault_cells(mesh, f));
  for (const SplitFault& f : split)
  {
    // A facet whose nodes are all tips stays inside the body (domain/faults.h):
    // it is no face, on either side.
    std::vector<std::size_t> opened;
    for (std::size_t k = 0; k < f.normals.size(); ++k)
      if (!std::equal(&f.plus_facets[d * k], &f.plus_facets[d * (k + 1)], &f.minus_facets[d * k]))
        opened.push_back(k);
    for (const auto* facets : {&f.plus_facets, &f.minus_facets})
    {
      const auto group = static_cast<std::int32_t>(mesh.names.size());
      mesh.names.push_back("fault." + f.name + (facets == &f.plus_facets ? "+" : "-"));
      for (std::size_t k : opened)
        mesh.facets.insert(mesh.facets.end(), facets->begin() + d * k, facets->begin() + d * (k + 1));
      mesh.facet_group.insert(mesh.facet_group.end(), opened.size(), group);
    }
    Fault fault;
    for (const auto& [plus, minus] : f.pairs)
      fault.pairs.push_back({plus, minus});
    fault.normals = pair_normals(f, d);
    fault.cells = std::move(cells[data.faults.size()]);
    data.faults.push_back(std::move(fault));
  }
  data.x = std::move(mesh.x);
  data.cells = std::move(mesh.cells);
  data.facets = std::move(mesh.facets);
  data.facet_group = std::move(mesh.facet_group);
  data.names = std::move(mesh.names);
}

/// Opens the scene's mesh in gmsh: a .msh as it is; a .geo from the mesh
/// cache where it holds it (domain/mesh_cache.h), else meshed (graded
/// toward the faults' tips, its sizes times mesh.size_factor), refined
/// mesh.refine times and, with a cache, stored there and read back.
void open_mesh(const Scene& scene)
{
  const std::string& file = scene.mesh.file;
  const std::string cached = mesh_cache_file(scene);
  if (!cached.empty() and std::filesystem::exists(cached))
  {
    gmsh::open(cached);
    return;
  }
  gmsh::open(file);
  if (std::filesystem::path(file).extension() == ".geo")
  {
    grade_toward_tips(scene);
    // After open(): the factor scales the .geo's sizes and its fields,
    // times the .geo's own factor, if it sets one.
    double own = 1;
    gmsh::option::getNumber("Mesh.MeshSizeFactor", own);
    gmsh::option::setNumber("Mesh.MeshSizeFactor", own * scene.mesh.size_factor);
    gmsh::model::mesh::generate(scene.mesh.dimension);
  }
  for (int i = 0; i < scene.mesh.refine; ++i)
    gmsh::model::mesh::refine();
  if (!cached.empty())
  {
    store_mesh(cached);
    gmsh::clear();
    gmsh::open(cached); // as every later run reads it
  }
}

GmshData read_gmsh_file(const Scene& scene)
{
  const std::string& file = scene.mesh.file;
  const int d = scene.mesh.dimension;
  GmshData data;
  gmsh::initialize();
  gmsh::option::setNumber("General.Terminal", 0);
  try
  {
    open_mesh(scene);
    std::vector<std::size_t> tags;
    std::vector<double> coords;
    gmsh::model::mesh::getNodes(tags, coords);
    std::map<std::size_t, std::int64_t> index;
    for (std::size_t i = 0; i < tags.size(); ++i)
    {
      index[tags[i]] = static_cast<std::int64_t>(i);
      for (int j = 0; j < d; ++j)
        data.x.push_back(coords[3 * i + j]);
    }
    // Cells: triangles (gmsh type 2) or tetrahedra (type 4).
    std::vector<std::size_t> element_tags, node_tags;
    gmsh::model::mesh::getElementsByType(d == 2 ? 2 : 4, element_tags, node_tags);
    for (std::size_t t : node_tags)
      data.cells.push_back(index.at(t));
    data.cell_region = regions_of_groups(scene, element_tags.size(), cell_groups(d, element_tags));
    // Boundaries: the named physical groups of dimension d-1.
    for_each_group(d - 1, d == 2 ? 1 : 2,
                   [&](const std::string& name, const std::vector<std::size_t>& etags,
                       const std::vector<std::size_t>& ntags)
                   {
                     const auto group = static_cast<std::int32_t>(data.names.size());
                     data.names.push_back(name);
                     for (std::size_t t : ntags)
                       data.facets.push_back(index.at(t));
                     data.facet_group.insert(data.facet_group.end(), etags.size(), group);
                   });
    check_fault_groups(scene);
  }
  catch (const SceneError&)
  {
    gmsh::finalize();
    throw;
  }
  catch (const std::exception& e)
  {
    gmsh::finalize();
    throw SceneError(file + ": cannot read the gmsh file: " + e.what());
  }
  catch (const std::string& e)
  {
    // The gmsh API reports its own errors by throwing their text.
    gmsh::finalize();
    throw SceneError(file + ": cannot read the gmsh file: " + (e.empty() ? "gmsh failed" : e));
  }
  gmsh::finalize();
  if (data.cells.empty())
    throw SceneError(file + ": no " + (d == 2 ? std::string("triangles") : "tetrahedra")
                     + " in the mesh (mesh.dimension = " + std::to_string(d) + ")");
  drop_unused_nodes(data, d);
  check_cells(scene, data);
  split_faults(scene, data);
  return data;
}

/// Every boundary the scene names is one of the mesh's physical groups
/// `groups` (of dimension d-1, the faults' faces not among them).
void check_boundary_names(const Scene& scene, const std::vector<std::string>& groups)
{
  for (const auto& [name, b] : scene.boundaries)
  {
    if (std::find(groups.begin(), groups.end(), name) == groups.end())
    {
      std::string known;
      for (const auto& n : groups)
        known += (known.empty() ? "" : ", ") + n;
      throw SceneError(scene.file + ": boundary." + name + ": unknown boundary name (" + scene.mesh.file
                       + " has physical groups " + (known.empty() ? "none" : known) + ")");
    }
  }
}

/// Rank 0's node pairs, normals and cells of each fault, on every rank.
void share_faults(std::vector<Fault>& faults, std::size_t count, MPI_Comm comm)
{
  faults.resize(count);
  for (Fault& f : faults)
  {
    long size = static_cast<long>(f.pairs.size());
    MPI_Bcast(&size, 1, MPI_LONG, 0, comm);
    f.pairs.resize(size);
    f.normals.resize(size);
    MPI_Bcast(f.pairs.data(), static_cast<int>(2 * size), MPI_INT64_T, 0, comm);
    MPI_Bcast(f.normals.data(), static_cast<int>(3 * size), MPI_DOUBLE, 0, comm);
    share_fault_cells(f.cells, comm);
  }
}

} // namespace

Domain read_gmsh(const Scene& scene, MPI_Comm world)
{
  const int d = scene.mesh.dimension;
  int rank = 0;
  MPI_Comm_rank(world, &rank);
  GmshData data;
  std::string error;
  if (rank == 0)
  {
    try
    {
      data = read_gmsh_file(scene);
    }
    catch (const SceneError& e)
    {
      error = e.what();
    }
  }
  // Every rank learns the outcome, the boundary names and the cells; the
  // others wait for rank 0 asleep.
  MPI_Request read;
  MPI_Ibarrier(world, &read);
  wait_quietly(read);
  std::string names = error.empty() ? "" : "!" + error;
  for (const std::string& n : data.names)
    names += n + "\n";
  int size = static_cast<int>(names.size());
  MPI_Bcast(&size, 1, MPI_INT, 0, world);
  names.resize(size);
  MPI_Bcast(names.data(), size, MPI_CHAR, 0, world);
  if (!names.empty() and names[0] == '!')
    throw SceneError(names.substr(1));
  std::vector<std::string> group_names;
  for (std::size_t start = 0, end; (end = names.find('\n', start)) != std::string::npos; start = end + 1)
    group_names.push_back(names.substr(start, end - start));
  const std::size_t boundaries = group_names.size() - 2 * scene.faults.size();
  check_boundary_names(scene, {group_names.begin(), group_names.begin() + boundaries});
  auto cells = static_cast<std::int64_t>(data.cells.size() / (d + 1));
  MPI_Bcast(&cells, 1, MPI_INT64_T, 0, world);
  MPI_Comm comm = working_communicator(world, cells, scene.solver.cells_per_rank);
  if (comm == MPI_COMM_NULL)
    return {}; // this rank waits

  const mesh::CellType cell = d == 2 ? mesh::CellType::triangle : mesh::CellType::tetrahedron;
  Domain domain;
  domain.mesh = std::make_shared<mesh::Mesh>(mesh::create_mesh(
      comm, graph::regular_adjacency_list(std::move(data.cells), d + 1),
      fem::CoordinateElement(cell, 1), data.x, {data.x.size() / d, std::size_t(d)},
      mesh::GhostMode::shared_facet));
  domain.mesh->topology_mutable().create_connectivity(d - 1, d);
  domain.mesh->topology_mutable().create_entities(d - 1);
  auto [entities, values] = io::xdmf_utils::distribute_entity_data(*domain.mesh, d - 1, data.facets,
                                                                    data.facet_group);
  const mesh::MeshTags<std::int32_t> tags = mesh::create_meshtags<std::int32_t>(
      domain.mesh, d - 1, graph::regular_adjacency_list(std::move(entities), d), values);

  domain.regions = locate_regions(scene, *domain.mesh, data.cell_region);
  auto group_facets = [&](std::size_t g)
  {
    std::vector<std::int32_t> facets;
    for (std::size_t i = 0; i < tags.indices().size(); ++i)
      if (tags.values()[i] == static_cast<std::int32_t>(g))
        facets.push_back(tags.indices()[i]);
    std::sort(facets.begin(), facets.end());
    return facets;
  };
  // The faults' faces are the last groups, + and - of each fault in turn.
  for (std::size_t g = 0; g < boundaries; ++g)
    domain.boundaries[group_names[g]] = group_facets(g);
  share_faults(data.faults, scene.faults.size(), comm);
  std::size_t k = 0;
  for (const auto& [name, spec] : scene.faults)
  {
    Fault& fault = domain.faults[name] = std::move(data.faults[k]);
    fault.plus_facets = group_facets(boundaries + 2 * k);
    fault.minus_facets = group_facets(boundaries + 2 * k + 1);
    ++k;
  }
  MPI_Comm_free(&comm); // the mesh holds its own duplicate
  return domain;
}

} // namespace biotcontact
