#include "domain/mesh_cache.h"

#include "domain/gmsh_api.h"

#include <cinttypes>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <optional>
#include <regex>
#include <set>
#include <unistd.h>

namespace biotcontact
{

namespace
{

const char* const VARIABLE = "BIOTCONTACT_MESH_CACHE";

/// A double as text that reads back to the same number.
std::string exact(double value)
{
  char text[32];
  std::snprintf(text, sizeof(text), "%.17g", value);
  return text;
}

/// FNV-1a, 64 bits, in 16 hex digits.
std::string fnv1a(const std::string& bytes)
{
  std::uint64_t hash = 14695981039346656037ULL;
  for (unsigned char c : bytes)
    hash = (hash ^ c) * 1099511628211ULL;
  char text[17];
  std::snprintf(text, sizeof(text), "%016" PRIx64, hash);
  return text;
}

/// The text of a .geo followed by that of each file it reads (Include,
/// Merge, ShapeFromFile with a name in quotes, relative to its directory),
/// depth first in the order they appear, each once; none when a file
/// cannot be read or names a file otherwise (a name gmsh computes).
std::optional<std::string> geo_inputs(const std::string& file, std::set<std::string>& visited)
{
  std::ifstream in(file, std::ios::binary);
  if (!in)
    return std::nullopt; // gmsh's open says why
  std::string text{std::istreambuf_iterator<char>(in), {}};
  static const std::regex reads("Include|Merge|ShapeFromFile");
  static const std::regex named(R"re((?:Include|Merge)\s*"([^"]*)"|ShapeFromFile\s*\(\s*"([^"]*)"\s*\))re");
  const auto count = [&text](const std::regex& r)
  { return std::distance(std::sregex_iterator(text.begin(), text.end(), r), std::sregex_iterator()); };
  if (count(reads) != count(named))
    return std::nullopt;
  const std::filesystem::path here = std::filesystem::path(file).parent_path();
  std::string inputs = text;
  for (auto m = std::sregex_iterator(text.begin(), text.end(), named); m != std::sregex_iterator(); ++m)
  {
    const std::string name = (*m)[1].matched ? (*m)[1].str() : (*m)[2].str();
    const std::string path = (here / name).lexically_normal().string();
    if (!visited.insert(path).second)
      continue;
    const std::optional<std::string> read = geo_inputs(path, visited);
    if (!read)
      return std::nullopt;
    inputs += "\nreads " + name + "\n" + *read;
  }
  return inputs;
}

} // namespace

std::string mesh_cache_key(const Scene& scene, const std::string& geo_text, const std::string& gmsh_version)
{
  std::string inputs = "biotcontact mesh cache 1\ngmsh " + gmsh_version + "\ndimension "
                       + std::to_string(scene.mesh.dimension) + "\nsize_factor " + exact(scene.mesh.size_factor)
                       + "\nrefine " + std::to_string(scene.mesh.refine) + "\n";
  for (const auto& [name, fault] : scene.faults) // by name, as the prototype sorts them
    if (fault.tip_size > 0)
      inputs += "tip " + name + " " + exact(fault.tip_size) + " " + exact(fault.tip_grading) + "\n";
  return fnv1a(inputs + "geo\n" + geo_text);
}

std::string mesh_cache_file(const Scene& scene)
{
  const char* directory = std::getenv(VARIABLE);
  if (!directory or !*directory or std::filesystem::path(scene.mesh.file).extension() != ".geo")
    return "";
  std::set<std::string> visited{std::filesystem::path(scene.mesh.file).lexically_normal().string()};
  const std::optional<std::string> text = geo_inputs(scene.mesh.file, visited);
  if (!text)
    return "";
  std::error_code error;
  std::filesystem::create_directories(directory, error);
  if (error)
    throw SceneError(std::string(VARIABLE) + "=" + directory + ": cannot make the directory: " + error.message());
  std::string version;
  gmsh::option::getString("General.Version", version);
  return (std::filesystem::path(directory) / (mesh_cache_key(scene, *text, version) + ".msh")).string();
}

void store_mesh(const std::string& file)
{
  // gmsh knows a file's format by its extension.
  const std::string part
      = std::filesystem::path(file).replace_extension(".part" + std::to_string(getpid()) + ".msh").string();
  gmsh::option::setNumber("Mesh.Binary", 1);
  gmsh::option::setNumber("Mesh.MshFileVersion", 4.1);
  gmsh::option::setNumber("Mesh.SaveAll", 1); // cells outside the physical groups too
  try
  {
    gmsh::write(part);
  }
  catch (const std::string& e)
  {
    std::error_code ignored;
    std::filesystem::remove(part, ignored);
    throw SceneError(std::string(VARIABLE) + ": cannot write " + part + ": " + e);
  }
  std::error_code error;
  std::filesystem::rename(part, file, error);
  if (error)
    throw SceneError(std::string(VARIABLE) + ": cannot write " + file + ": " + error.message());
}

} // namespace biotcontact
