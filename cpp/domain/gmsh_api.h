// The part of gmsh's C++ API (gmsh.h) that the mesh reader uses, under the
// same names, over gmsh's C API in a libgmsh opened on the first call. A
// run on a built-in mesh, and every input refused before a mesh is read,
// then starts without gmsh and its ~90 libraries (0.12 s of each launch;
// docs/performance.md, "Start-up"). The prototype imports its gmsh module
// where it reads a mesh, the same deferral (so no Python twin).
#pragma once

#include <string>
#include <utility>
#include <vector>

/// gmsh's functions as gmsh.h declares them; each throws the text of
/// gmsh's last error (a std::string, as gmsh.h's do) when gmsh fails, and
/// the first throws std::runtime_error when libgmsh cannot be opened.
namespace biotcontact::gmsh
{
using vectorpair = std::vector<std::pair<int, int>>;

void initialize();
void finalize();
void open(const std::string& file);
void write(const std::string& file);
void clear();

namespace option
{
void setNumber(const std::string& name, double value);
void getNumber(const std::string& name, double& value);
void getString(const std::string& name, std::string& value);
}

namespace model
{
void getEntities(vectorpair& dim_tags, int dim);
void getBoundary(const vectorpair& dim_tags, vectorpair& out, bool combined, bool oriented, bool recursive);
void getPhysicalGroups(vectorpair& dim_tags, int dim = -1);
void getPhysicalName(int dim, int tag, std::string& name);
void getEntitiesForPhysicalGroup(int dim, int tag, std::vector<int>& tags);

namespace mesh
{
void generate(int dim);
void refine();
/// Nodes of the whole model (gmsh's dim = -1, tag = -1).
void getNodes(std::vector<std::size_t>& tags, std::vector<double>& coords);
void getElementsByType(int type, std::vector<std::size_t>& element_tags, std::vector<std::size_t>& node_tags,
                       int tag = -1);

namespace field
{
int add(const std::string& type);
void setNumber(int tag, const std::string& option, double value);
void setNumbers(int tag, const std::string& option, const std::vector<double>& values);
void setString(int tag, const std::string& option, const std::string& value);
void setAsBackgroundMesh(int tag);
} // namespace field
} // namespace mesh
} // namespace model
} // namespace biotcontact::gmsh
