#include "domain/tip_grading.h"

#include "domain/gmsh_api.h"

#include <algorithm>
#include <optional>
#include <set>
#include <sstream>

namespace biotcontact
{

namespace
{
using DimTags = std::vector<std::pair<int, int>>;

/// The entities of dimension `dim` on the boundary of `entities`: of their
/// union (`combined`: a boundary shared by two of them is not one), or of
/// each.
std::set<int> boundary_of(const DimTags& entities, bool combined)
{
  DimTags boundary;
  gmsh::model::getBoundary(entities, boundary, combined, false, false);
  std::set<int> tags;
  for (const auto& [dim, tag] : boundary)
    tags.insert(tag);
  return tags;
}

/// The entities of the outer boundary of the body (dimension d - 2): the
/// points (2D) or curves (3D) of its boundary curves (surfaces).
std::set<int> outer_edges(int d)
{
  DimTags body;
  gmsh::model::getEntities(body, d);
  DimTags faces;
  for (int tag : boundary_of(body, true))
    faces.emplace_back(d - 1, tag);
  return boundary_of(faces, false);
}

/// The tips of the fault group `name` (dimension d - 2: points in 2D,
/// curves in 3D): the edges of its entities' union that are not on the
/// outer boundary. Nothing when the mesh has no such group (read_gmsh says
/// so).
std::optional<std::vector<double>> tips_of(const std::string& name, int d)
{
  DimTags groups;
  gmsh::model::getPhysicalGroups(groups, d - 1);
  DimTags entities;
  for (const auto& [dim, tag] : groups)
  {
    std::string group;
    gmsh::model::getPhysicalName(dim, tag, group);
    std::vector<int> tags;
    if (group == name)
      gmsh::model::getEntitiesForPhysicalGroup(dim, tag, tags);
    for (int t : tags)
      entities.emplace_back(d - 1, t);
  }
  if (entities.empty())
    return std::nullopt;
  std::vector<double> tips;
  const std::set<int> outer = outer_edges(d);
  for (int tag : boundary_of(entities, true))
    if (!outer.count(tag))
      tips.push_back(tag);
  return tips;
}

std::string number_text(double v)
{
  std::ostringstream s;
  s.precision(17);
  s << v;
  return s.str();
}
} // namespace

void grade_toward_tips(const Scene& scene)
{
  const int d = scene.mesh.dimension;
  std::vector<double> sizes;
  for (const auto& [name, fault] : scene.faults)
  {
    if (fault.tip_size <= 0)
      continue;
    const std::string key = scene.file + ": fault." + name + ".tip_size: ";
    const std::optional<std::vector<double>> tips = tips_of(name, d);
    if (!tips) // no such group: read_gmsh names it
      continue;
    if (tips->empty())
      throw SceneError(key + "the fault has no tip inside the body (its edges are all on the outer boundary)");
    const int distance = gmsh::model::mesh::field::add("Distance");
    if (sizes.empty() and distance != 1)
      throw SceneError(key + scene.mesh.file + " sets size fields of its own, which the tips' would replace: "
                       + "grade the tips there, or drop its fields");
    gmsh::model::mesh::field::setNumbers(distance, d == 2 ? "PointsList" : "CurvesList", *tips);
    if (d == 3) // points along each tip curve, 1/1000 of its length apart
      gmsh::model::mesh::field::setNumber(distance, "NumPointsPerCurve", 1000);
    const int size = gmsh::model::mesh::field::add("MathEval");
    gmsh::model::mesh::field::setString(size, "F", number_text(fault.tip_size) + " + "
                                                       + number_text(fault.tip_grading) + " * F"
                                                       + std::to_string(distance));
    sizes.push_back(size);
  }
  if (sizes.empty())
    return;
  const int smallest = gmsh::model::mesh::field::add("Min");
  gmsh::model::mesh::field::setNumbers(smallest, "FieldsList", sizes);
  gmsh::model::mesh::field::setAsBackgroundMesh(smallest);
}

} // namespace biotcontact
