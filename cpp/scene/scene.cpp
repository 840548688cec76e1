#include "scene/scene.h"

#include "scene/fault_input.h"
#include "scene/physics_input.h"
#include "scene/run_input.h"
#include "scene/section.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <functional>
#include <iomanip>
#include <memory>
#include <numeric>
#include <set>
#include <sstream>
#include <toml++/toml.h>
#include <unistd.h>

namespace biotcontact
{
namespace
{

MeshSpec read_mesh(Section s, const std::string& scene_file)
{
  MeshSpec m;
  m.type = s.choice<MeshType>("type");
  if (m.type == MeshType::rectangle or m.type == MeshType::box)
  {
    const std::size_t d = m.type == MeshType::rectangle ? 2 : 3;
    m.dimension = static_cast<int>(d);
    m.lower = s.has("lower") ? s.number_vector("lower", d) : std::vector<double>(d, 0.0);
    m.upper = s.number_vector("upper", d);
    const std::vector<double> n = s.number_vector("cells", d);
    for (std::size_t i = 0; i < d; ++i)
    {
      if (m.upper[i] <= m.lower[i])
        s.fail("upper", "must be above mesh.lower in every direction");
      if (n[i] < 1 or n[i] != std::floor(n[i]))
        s.fail("cells", "must be positive integers");
      m.cells.push_back(static_cast<std::size_t>(n[i]));
    }
    // Refused before any allocation: the peak memory per simplex measured
    // on the default scene and the 3D block (docs/performance.md, about
    // 4 kB per triangle and 25 kB per tetrahedron with direct solvers).
    const double simplices = (d == 2 ? 4.0 : 6.0) * std::accumulate(n.begin(), n.end(), 1.0, std::multiplies<>());
    const double need = simplices * (d == 2 ? 4e3 : 25e3);
    const double have = static_cast<double>(sysconf(_SC_PHYS_PAGES)) * static_cast<double>(sysconf(_SC_PAGE_SIZE));
    if (have > 0 and need > have)
    {
      std::ostringstream message;
      message << std::setprecision(2) << simplices << " cells need about " << need / 1e9
              << " GB of memory; this machine has " << have / 1e9 << " GB";
      s.fail("cells", message.str());
    }
  }
  else
  {
    const std::string name = s.string("file");
    namespace fs = std::filesystem;
    // Mesh files are looked up next to the scene, then in meshes/.
    const fs::path here = fs::path(scene_file).parent_path();
    for (const fs::path& candidate :
         {here / name, here / ".." / "meshes" / name, fs::path(name)})
    {
      if (fs::exists(candidate))
      {
        m.file = candidate.lexically_normal().string();
        break;
      }
    }
    if (m.file.empty())
      s.fail("file", "mesh file not found: " + name);
    m.dimension = s.integer("dimension", 2);
    if (m.dimension != 2 and m.dimension != 3)
      s.fail("dimension", "must be 2 or 3");
    // Each refinement splits every simplex into 2^d: nested meshes, as
    // the studies' references need (tools/study.py maps nodes by position).
    m.refine = s.integer("refine", 0);
    if (m.refine < 0 or m.refine > 6)
      s.fail("refine", "must be an integer in [0, 6]");
    // Any fineness between the refinements' halvings (a 3D study's levels:
    // each refinement costs 8x), at the price of meshes that do not nest.
    m.size_factor = s.number("size_factor", 1.0);
    if (!(m.size_factor > 0 and std::isfinite(m.size_factor)))
      s.fail("size_factor", "must be a finite number > 0");
    if (s.has("size_factor") and std::filesystem::path(m.file).extension() != ".geo")
      s.fail("size_factor", "needs a .geo mesh file, which gmsh meshes here (" + m.file
                                + " is meshed already: use mesh.refine)");
  }
  s.finish();
  return m;
}

/// The scene file as a TOML table, with the --set overrides applied.
toml::table parse_scene(const std::string& file, const std::vector<std::string>& overrides)
{
  if (!std::filesystem::is_regular_file(file))
    throw SceneError(file + ": scene file not found");
  toml::table root;
  try
  {
    root = toml::parse_file(file);
  }
  catch (const toml::parse_error& e)
  {
    throw SceneError(file + ":" + std::to_string(e.source().begin.line)
                     + ": invalid TOML: " + std::string(e.description()));
  }
  for (const std::string& o : overrides)
    apply_override(root, o, file);
  return root;
}

/// The identifiers an expression already knows (expression.cpp: muparser's
/// variables, constants and functions), which no name may take.
const std::set<std::string> reserved_identifiers
    = {"x",    "y",     "z",     "t",    "pi",    "_pi",   "_e",    "sin",  "cos",  "tan",  "asin",
       "acos", "atan",  "sinh",  "cosh", "tanh",  "asinh", "acosh", "atanh", "exp", "log",  "ln",
       "log2", "log10", "sqrt",  "abs",  "sign",  "rint",  "min",   "max",   "sum", "avg"};

/// The text of `name` with the names it uses substituted, resolving them
/// first (depth first); `path` holds the names being resolved, so that a
/// cycle is refused naming it.
const std::string& resolve_name(const std::string& name, const Names& given, Names& resolved,
                                std::vector<std::string>& path, const Section& s)
{
  if (auto it = resolved.find(name); it != resolved.end())
    return it->second;
  if (std::find(path.begin(), path.end(), name) != path.end())
  {
    std::string cycle;
    for (auto it = std::find(path.begin(), path.end(), name); it != path.end(); ++it)
      cycle += *it + " -> ";
    s.fail(path.front(), "the names refer to one another in a cycle (" + cycle + name + ")");
  }
  path.push_back(name);
  for (const std::string& used : identifiers(given.at(name)))
    if (given.count(used))
      resolve_name(used, given, resolved, path, s);
  path.pop_back();
  return resolved[name] = substitute_names(given.at(name), resolved);
}

/// [expressions]: names for numbers and expressions of x, y, z, t, each
/// usable in every expression of the scene and in the other names' (in
/// any order, without a cycle); each is parsed as every expression is.
std::shared_ptr<const Names> read_names(Section s)
{
  Names given, resolved;
  for (const std::string& name : s.keys())
  {
    if (identifiers(name) != std::vector<std::string>{name} or reserved_identifiers.count(name))
      s.fail(name, "not a name: a letter or _ then letters, digits or _, none of x, y, z, t, pi and the "
                   "functions of an expression");
    const toml::node* n = s.node(name);
    if (n->is_number())
      given[name] = Expression(n->value<double>().value()).text();
    else if (n->is_string())
      given[name] = n->value<std::string>().value();
    else
      s.fail(name, "must be a number or an expression string");
  }
  std::vector<std::string> path;
  for (const auto& [name, text] : given)
  {
    resolve_name(name, given, resolved, path, s);
    try
    {
      Expression(resolved.at(name), text);
    }
    catch (const std::invalid_argument& e)
    {
      s.fail(name, e.what());
    }
  }
  s.finish();
  return std::make_shared<const Names>(std::move(resolved));
}

/// [scene]: the name (the file's stem by default) and description.
void read_meta(Section& top, Scene& scene)
{
  Section meta = top.table("scene", false);
  scene.name = meta.string("name", std::filesystem::path(scene.file).stem().string());
  scene.description = meta.string("description", "");
  meta.finish();
}

} // namespace

Scene read_scene(const std::string& file, const std::vector<std::string>& overrides)
{
  toml::table root = parse_scene(file, overrides);
  Scene scene;
  scene.file = file;
  Section top(&root, "", file);
  top.set_names(read_names(top.table("expressions", false)));
  read_meta(top, scene);
  scene.mesh = read_mesh(top.table("mesh", true), file);
  top.set_axes(scene.mesh.dimension);
  read_physics(top, scene);
  read_time(top, scene);
  read_output(top.table("output", false), scene);
  read_solver(top.table("solver", false), scene.mesh.dimension, scene.solver);
  read_boundaries(top.table("boundary", false), scene);
  read_faults(top.table("fault", false), scene);
  read_wells(top.table("well", false), scene);
  read_regions(top.table("region", false), root, scene);
  if (top.has("reference"))
    read_reference(top.table("reference", true), scene);
  top.finish();
  return scene;
}

std::string agreed_error(const std::string& message, MPI_Comm comm)
{
  int size = 1, rank = 0;
  MPI_Comm_size(comm, &size);
  MPI_Comm_rank(comm, &rank);
  const int mine = message.empty() ? size : rank;
  int owner = size;
  MPI_Allreduce(&mine, &owner, 1, MPI_INT, MPI_MIN, comm);
  if (owner == size)
    return "";
  int length = static_cast<int>(message.size());
  MPI_Bcast(&length, 1, MPI_INT, owner, comm);
  std::string text = message;
  text.resize(length);
  MPI_Bcast(text.data(), length, MPI_CHAR, owner, comm);
  return text;
}

void agree_on_error(const std::string& message, MPI_Comm comm)
{
  if (const std::string text = agreed_error(message, comm); !text.empty())
    throw SceneError(text);
}

} // namespace biotcontact
