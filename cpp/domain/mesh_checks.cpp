// The scene checked against its mesh (domain/mesh_checks.h).
#include "domain/mesh_checks.h"

#include "domain/wells.h"

#include <cmath>
#include <numeric>
#include <sstream>
#include <dolfinx/common/IndexMap.h>
#include <dolfinx/mesh/utils.h>

namespace biotcontact
{
using namespace dolfinx;

namespace
{
/// The first expression of a list that is not finite somewhere: its key
/// and a description of where.
struct NonFinite
{
  int index = -1;
  std::string message;
};

/// Coordinates (3 per point) of the vertices of some facets.
std::vector<double> facet_vertices(const mesh::Mesh& mesh, const std::vector<std::int32_t>& facets)
{
  const int fdim = mesh.topology().dim() - 1;
  const auto nodes = mesh::entities_to_geometry(mesh, fdim, facets, false);
  std::span<const double> x = mesh.geometry().x();
  std::vector<double> points;
  for (std::int32_t node : nodes)
    points.insert(points.end(), x.begin() + 3 * node, x.begin() + 3 * node + 3);
  return points;
}

std::vector<double> cell_midpoints(const mesh::Mesh& mesh)
{
  const int tdim = mesh.topology().dim();
  const std::int32_t n = mesh.topology().index_map(tdim)->size_local();
  std::vector<std::int32_t> cells(n);
  std::iota(cells.begin(), cells.end(), 0);
  return mesh::compute_midpoints(mesh, tdim, cells);
}
} // namespace

namespace
{
/// An expression the run will evaluate: its key, and the points (3 per
/// point) and times where.
struct Use
{
  std::string key;
  const Expression* expression;
  const std::vector<double>* points;
  bool time_dependent_use;
};

/// The volume terms, evaluated at the cell midpoints.
void add_volume_uses(const Scene& scene, const std::vector<double>& midpoints, std::vector<Use>& uses)
{
  if (scene.mechanics and scene.mechanics->body_force)
    for (const Expression& e : *scene.mechanics->body_force)
      uses.push_back({"mechanics.body_force", &e, &midpoints, true});
  if (scene.mechanics and scene.mechanics->pore_pressure)
    uses.push_back({"mechanics.pore_pressure", &*scene.mechanics->pore_pressure, &midpoints, true});
  if (scene.flow)
  {
    if (scene.flow->source)
      uses.push_back({"flow.source", &*scene.flow->source, &midpoints, true});
    if (scene.flow->permeability)
      uses.push_back({"flow.permeability", &*scene.flow->permeability, &midpoints, false});
    uses.push_back({"flow.initial_pressure", &scene.flow->initial_pressure, &midpoints, false});
  }
  for (const auto& [name, r] : scene.regions)
  {
    if (r.where)
      uses.push_back({"region." + name + ".where", &*r.where, &midpoints, false});
    if (r.body_force)
      for (const Expression& e : *r.mechanics->body_force)
        uses.push_back({"region." + name + ".body_force", &e, &midpoints, true});
    if (r.flow and r.flow->permeability)
      uses.push_back({"region." + name + ".permeability", &*r.flow->permeability, &midpoints, false});
  }
}

/// The first use whose value is not finite on this rank, and its message.
NonFinite first_non_finite(const Scene& scene, int d, const std::vector<Use>& uses)
{
  NonFinite found;
  for (std::size_t k = 0; k < uses.size() and found.index < 0; ++k)
  {
    const Use& use = uses[k];
    const std::vector<double>& p = *use.points;
    for (double t : use.time_dependent_use ? std::vector<double>{0.0, scene.end_time} : std::vector<double>{0.0})
    {
      for (std::size_t i = 0; i + 2 < p.size() and found.index < 0; i += 3)
      {
        const double v = (*use.expression)(&p[i], t);
        if (!std::isfinite(v))
        {
          std::ostringstream s;
          s << scene.file << ": " << use.key << ": \"" << use.expression->text() << "\" is "
            << (std::isnan(v) ? "NaN" : v > 0 ? "inf" : "-inf") << " at (" << p[i] << ", " << p[i + 1];
          if (d == 3)
            s << ", " << p[i + 2];
          s << "), t = " << t;
          found = {static_cast<int>(k), s.str()};
        }
      }
    }
  }
  return found;
}
} // namespace

namespace
{
void check_foundation_normals(const Scene& scene, const Domain& domain);
} // namespace

void check_expressions(const Scene& scene, const Domain& domain, MPI_Comm comm)
{
  std::vector<Use> uses;
  std::map<std::string, std::vector<double>> boundary_points;
  for (const auto& [name, b] : scene.boundaries)
    if (domain.boundaries.count(name))
      boundary_points[name] = facet_vertices(*domain.mesh, domain.boundaries.at(name));
  for (const auto& [name, b] : scene.boundaries)
  {
    const std::vector<double>* at = &boundary_points[name];
    const std::string key = "boundary." + name;
    for (std::size_t i = 0; i < b.displacement.size(); ++i)
      if (b.displacement[i])
        uses.push_back({key + ".displacement." + "xyz"[i], &*b.displacement[i], at, true});
    for (const Expression& e : b.traction)
      uses.push_back({key + ".traction", &e, at, true});
    if (b.flow == BoundarySpec::Flow::pressure)
      uses.push_back({key + ".pressure", &b.pressure, at, true});
    if (b.flow == BoundarySpec::Flow::flux)
      uses.push_back(b.rate ? Use{key + ".rate", &*b.rate, at, true} : Use{key + ".flux", &b.flux, at, true});
  }
  std::map<std::string, std::vector<double>> fault_points;
  for (const auto& [name, f] : scene.faults)
    if (f.pressure and domain.faults.count(name))
    {
      fault_points[name] = facet_vertices(*domain.mesh, domain.faults.at(name).plus_facets);
      uses.push_back({"fault." + name + ".pressure", &*f.pressure, &fault_points[name], true});
    }
  std::map<std::string, std::vector<double>> well_points;
  for (const auto& [name, w] : scene.wells)
  {
    well_points[name] = {w.position[0], w.position[1], w.bottom};
    uses.push_back({"well." + name + ".rate", &w.rate, &well_points[name], true});
  }
  const std::vector<double> midpoints = cell_midpoints(*domain.mesh);
  add_volume_uses(scene, midpoints, uses);
  agree_on_error(first_non_finite(scene, domain.dim(), uses).message, comm);
  check_foundation_normals(scene, domain);
  for (const auto& [name, b] : scene.boundaries)
    if (b.flow == BoundarySpec::Flow::flux)
      planar_boundary(domain, name, scene.file + ": boundary." + name + (b.rate ? ".rate" : ".flux"));
  for (const auto& [name, w] : scene.wells)
  {
    locate_well(domain, w, scene.file + ": well." + name + ".position");
    if (!w.fault.empty() and well_cells(domain.faults.at(w.fault).cells, w).cells.empty())
      throw SceneError(scene.file + ": well." + name + ".position: the well at " + well_place(w, domain.dim())
                       + " is not on fault." + w.fault);
  }
}

namespace
{
/// The outward unit normal and the measure of one exterior facet, from its
/// vertices (a, b[, c]) and the midpoint of its cell.
std::pair<std::array<double, 3>, double> facet_normal(const double* a, const double* b, const double* c, int d,
                                                      std::span<const double> cell_midpoint)
{
  std::array<double, 3> n{};
  if (d == 2)
    n = {b[1] - a[1], a[0] - b[0], 0.0};
  else
    for (int i = 0; i < 3; ++i)
    {
      const int j = (i + 1) % 3, k = (i + 2) % 3;
      n[i] = (b[j] - a[j]) * (c[k] - a[k]) - (b[k] - a[k]) * (c[j] - a[j]);
    }
  double length = 0, outward = 0;
  for (int i = 0; i < 3; ++i)
  {
    length += n[i] * n[i];
    outward += n[i] * (a[i] - cell_midpoint[i]);
  }
  length = std::sqrt(length);
  for (double& ni : n)
    ni *= (outward < 0 ? -1.0 : 1.0) / length;
  return {n, d == 2 ? length : length / 2};
}
} // namespace

namespace
{
/// A foundation's normal is the direction in which its face moves to touch
/// it: outward. One that points into the body (on average over the face)
/// holds nothing, and the run would have no contact at all: refused, the
/// same on every rank (collective).
void check_foundation_normals(const Scene& scene, const Domain& domain)
{
  const mesh::Mesh& mesh = *domain.mesh;
  const int d = mesh.topology().dim();
  const std::int32_t owned = mesh.topology().index_map(d - 1)->size_local();
  auto f_to_c = mesh.topology().connectivity(d - 1, d);
  for (const auto& [name, b] : scene.boundaries)
  {
    if (!b.contact)
      continue;
    const std::vector<std::int32_t>& facets = domain.boundaries.at(name);
    const std::vector<double> x = facet_vertices(mesh, facets);
    std::vector<std::int32_t> cells;
    for (std::int32_t f : facets)
      cells.push_back(f_to_c->links(f)[0]);
    const std::vector<double> midpoints = mesh::compute_midpoints(mesh, d, cells);
    double along = 0; // the measure-weighted nu.n_out
    for (std::size_t k = 0; k < facets.size(); ++k)
    {
      if (facets[k] >= owned)
        continue;
      const double* v = &x[3 * d * k];
      auto [n, measure] = facet_normal(v, v + 3, v + 6, d, std::span(midpoints.data() + 3 * k, 3));
      std::array<double, 3> middle{0, 0, 0}, nu{0, 0, 0};
      for (int j = 0; j < d; ++j)
        for (int i = 0; i < 3; ++i)
          middle[i] += v[3 * j + i] / d;
      for (int i = 0; i < d; ++i)
        nu[i] = b.contact->normal[i](middle.data(), 0.0);
      const double length = std::hypot(nu[0], nu[1], nu[2]), dot = nu[0] * n[0] + nu[1] * n[1] + nu[2] * n[2];
      if (length > 0 and std::isfinite(dot / length))
        along += measure * dot / length;
    }
    MPI_Allreduce(MPI_IN_PLACE, &along, 1, MPI_DOUBLE, MPI_SUM, mesh.comm());
    if (along < 0)
      throw SceneError(scene.file + ": boundary." + name + ".contact.normal: points into the body: it is the "
                       "direction in which the face moves to touch the foundation, outward from the body");
  }
}
} // namespace

PlanarBoundary planar_boundary(const Domain& domain, const std::string& name, const std::string& key)
{
  const mesh::Mesh& mesh = *domain.mesh;
  const int d = mesh.topology().dim();
  const std::vector<std::int32_t>& facets = domain.boundaries.at(name);
  const std::vector<double> x = facet_vertices(mesh, facets);
  auto f_to_c = mesh.topology().connectivity(d - 1, d);
  std::vector<std::int32_t> cells;
  for (std::int32_t f : facets)
    cells.push_back(f_to_c->links(f)[0]);
  const std::vector<double> midpoints = mesh::compute_midpoints(mesh, d, cells);
  const std::int32_t owned = mesh.topology().index_map(d - 1)->size_local();
  std::vector<std::array<double, 3>> normals;
  std::array<double, 4> sum{}; // the measure-weighted normal and the measure, over owned facets
  for (std::size_t k = 0; k < facets.size(); ++k)
  {
    const double* v = &x[3 * d * k];
    auto [n, measure] = facet_normal(v, v + 3, v + 6, d, std::span(midpoints.data() + 3 * k, 3));
    normals.push_back(n);
    for (int i = 0; i < 3 and facets[k] < owned; ++i)
      sum[i] += measure * n[i];
    sum[3] += facets[k] < owned ? measure : 0.0;
  }
  MPI_Allreduce(MPI_IN_PLACE, sum.data(), 4, MPI_DOUBLE, MPI_SUM, mesh.comm());
  PlanarBoundary p;
  const double length = std::sqrt(sum[0] * sum[0] + sum[1] * sum[1] + sum[2] * sum[2]);
  for (int i = 0; i < 3; ++i)
    p.normal[i] = sum[i] / length;
  p.measure = sum[3];
  double deviation = 0;
  for (const auto& n : normals)
    deviation = std::max(deviation, std::hypot(n[0] - p.normal[0], n[1] - p.normal[1], n[2] - p.normal[2]));
  MPI_Allreduce(MPI_IN_PLACE, &deviation, 1, MPI_DOUBLE, MPI_MAX, mesh.comm());
  if (!(deviation < 1e-6))
  {
    std::ostringstream s;
    s << key << ": the boundary " << name << " is not planar (its facet normals differ from their mean by up to "
      << deviation << "); a flux or rate is prescribed on planar boundaries only";
    throw SceneError(s.str());
  }
  return p;
}

} // namespace biotcontact
