#include "domain/gmsh_api.h"

#include <dlfcn.h>
#include <stdexcept>

namespace biotcontact::gmsh
{

namespace
{

/// libgmsh, opened on the first call (BIOTCONTACT_GMSH_LIBRARY: the file
/// the build linked against, CMakeLists.txt).
void* library()
{
  static void* handle = []
  {
    void* h = dlopen(BIOTCONTACT_GMSH_LIBRARY, RTLD_NOW | RTLD_LOCAL);
    if (!h)
      throw std::runtime_error(std::string("cannot load gmsh: ") + dlerror());
    return h;
  }();
  return handle;
}

template <typename F>
F* symbol(const char* name)
{
  void* f = dlsym(library(), name);
  if (!f)
    throw std::runtime_error(std::string("cannot load gmsh: no ") + name + " in " + BIOTCONTACT_GMSH_LIBRARY);
  return reinterpret_cast<F*>(f);
}

/// Frees what gmsh allocated.
void release(void* data) { symbol<void(void*)>("gmshFree")(data); }

/// Throws the text of gmsh's last error if its error flag is set.
void check(int ierr)
{
  if (!ierr)
    return;
  char* text = nullptr;
  int again = 0;
  symbol<void(char**, int*)>("gmshLoggerGetLastError")(&text, &again);
  std::string error = text ? text : "";
  release(text);
  throw error;
}

/// Calls gmsh's C function `name` with `args` and its error flag. The C
/// signature is the arguments' types followed by int* ierr (gmshc.h).
template <typename... Args>
void call(const char* name, Args... args)
{
  int ierr = 0;
  symbol<void(Args..., int*)>(name)(args..., &ierr);
  check(ierr);
}

/// The n values at `data`, which gmsh allocated and the caller now frees.
template <typename T>
std::vector<T> taken(T* data, std::size_t n)
{
  std::vector<T> values(data, data + n);
  release(data);
  return values;
}

vectorpair pairs(int* data, std::size_t n)
{
  const std::vector<int> flat = taken(data, n);
  vectorpair out;
  for (std::size_t i = 0; i + 1 < flat.size(); i += 2)
    out.emplace_back(flat[i], flat[i + 1]);
  return out;
}

} // namespace

void initialize() { call("gmshInitialize", 0, static_cast<char**>(nullptr), 1); }
void finalize() { call("gmshFinalize"); }
void open(const std::string& file) { call("gmshOpen", file.c_str()); }
void write(const std::string& file) { call("gmshWrite", file.c_str()); }
void clear() { call("gmshClear"); }
void option::setNumber(const std::string& name, double value) { call("gmshOptionSetNumber", name.c_str(), value); }

void option::getNumber(const std::string& name, double& value) { call("gmshOptionGetNumber", name.c_str(), &value); }

void option::getString(const std::string& name, std::string& value)
{
  char* text = nullptr;
  call("gmshOptionGetString", name.c_str(), &text);
  value = text ? text : "";
  release(text);
}

void model::getEntities(vectorpair& dim_tags, int dim)
{
  int* data = nullptr;
  std::size_t n = 0;
  call("gmshModelGetEntities", &data, &n, dim);
  dim_tags = pairs(data, n);
}

void model::getBoundary(const vectorpair& dim_tags, vectorpair& out, bool combined, bool oriented, bool recursive)
{
  std::vector<int> flat;
  for (const auto& [dim, tag] : dim_tags)
    flat.insert(flat.end(), {dim, tag});
  int* data = nullptr;
  std::size_t n = 0;
  call("gmshModelGetBoundary", flat.data(), flat.size(), &data, &n, int(combined), int(oriented), int(recursive));
  out = pairs(data, n);
}

void model::getPhysicalGroups(vectorpair& dim_tags, int dim)
{
  int* data = nullptr;
  std::size_t n = 0;
  call("gmshModelGetPhysicalGroups", &data, &n, dim);
  dim_tags = pairs(data, n);
}

void model::getPhysicalName(int dim, int tag, std::string& name)
{
  char* text = nullptr;
  call("gmshModelGetPhysicalName", dim, tag, &text);
  name = text ? text : "";
  release(text);
}

void model::getEntitiesForPhysicalGroup(int dim, int tag, std::vector<int>& tags)
{
  int* data = nullptr;
  std::size_t n = 0;
  call("gmshModelGetEntitiesForPhysicalGroup", dim, tag, &data, &n);
  tags = taken(data, n);
}

void model::mesh::generate(int dim) { call("gmshModelMeshGenerate", dim); }
void model::mesh::refine() { call("gmshModelMeshRefine"); }

void model::mesh::getNodes(std::vector<std::size_t>& tags, std::vector<double>& coords)
{
  std::size_t *tag_data = nullptr, n_tags = 0, n_coords = 0, n_parametric = 0;
  double *coord_data = nullptr, *parametric = nullptr;
  call("gmshModelMeshGetNodes", &tag_data, &n_tags, &coord_data, &n_coords, &parametric, &n_parametric, -1, -1, 0, 0);
  tags = taken(tag_data, n_tags);
  coords = taken(coord_data, n_coords);
  release(parametric); // none asked for
}

void model::mesh::getElementsByType(int type, std::vector<std::size_t>& element_tags,
                                    std::vector<std::size_t>& node_tags, int tag)
{
  std::size_t *elements = nullptr, *nodes = nullptr, n_elements = 0, n_nodes = 0;
  call("gmshModelMeshGetElementsByType", type, &elements, &n_elements, &nodes, &n_nodes, tag, std::size_t(0),
       std::size_t(1));
  element_tags = taken(elements, n_elements);
  node_tags = taken(nodes, n_nodes);
}

int model::mesh::field::add(const std::string& type)
{
  int ierr = 0;
  const int tag = symbol<int(const char*, int, int*)>("gmshModelMeshFieldAdd")(type.c_str(), -1, &ierr);
  check(ierr);
  return tag;
}

void model::mesh::field::setNumber(int tag, const std::string& option, double value)
{
  call("gmshModelMeshFieldSetNumber", tag, option.c_str(), value);
}

void model::mesh::field::setNumbers(int tag, const std::string& option, const std::vector<double>& values)
{
  std::vector<double> copy = values; // gmshc.h takes double*
  call("gmshModelMeshFieldSetNumbers", tag, option.c_str(), copy.data(), copy.size());
}

void model::mesh::field::setString(int tag, const std::string& option, const std::string& value)
{
  call("gmshModelMeshFieldSetString", tag, option.c_str(), value.c_str());
}

void model::mesh::field::setAsBackgroundMesh(int tag) { call("gmshModelMeshFieldSetAsBackgroundMesh", tag); }

} // namespace biotcontact::gmsh
