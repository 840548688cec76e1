#include "scene/fault_input.h"

#include <filesystem>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <string>
#include <vector>

namespace biotcontact
{
namespace
{

/// friction, cohesion or tresca of a contact table or a fault (FrictionSpec).
FrictionSpec read_friction(Section& s)
{
  FrictionSpec f;
  f.friction = s.number("friction", 0.0);
  if (!(f.friction >= 0 and std::isfinite(f.friction)))
    s.fail("friction", "must be a finite number >= 0 (the Coulomb coefficient)");
  f.cohesion = s.number("cohesion", 0.0);
  if (!(f.cohesion >= 0 and std::isfinite(f.cohesion)))
    s.fail("cohesion", "must be a finite number >= 0 (Pa)");
  if (s.has("tresca"))
  {
    if (s.has("friction") or s.has("cohesion"))
      s.fail("tresca", "give tresca (a given bound) or friction and cohesion (Coulomb), not both");
    f.tresca = s.number("tresca");
    if (!(*f.tresca >= 0 and std::isfinite(*f.tresca)))
      s.fail("tresca", "must be a finite number >= 0 (Pa)");
  }
  return f;
}

/// contact = { gap = .., normal = [..], friction.. }: the foundation of a
/// contact boundary.
ContactSpec read_contact(Section c, int d)
{
  ContactSpec contact;
  const std::optional<Expression> gap = c.expression("gap");
  if (!gap)
    c.fail("gap", "missing (the gap g_a to the foundation)");
  contact.gap = *gap;
  if (contact.gap.depends_on_time())
    c.fail("gap", "must not depend on t");
  contact.normal = c.expression_vector("normal", d);
  double length = 0;
  bool constant = true;
  for (const Expression& n : contact.normal)
  {
    if (n.depends_on_time())
      c.fail("normal", "must not depend on t");
    constant = constant and n.is_constant();
    length += n.is_constant() ? n(0, 0, 0, 0) * n(0, 0, 0, 0) : 0.0;
  }
  // A normal that varies in space is checked at every contact node.
  if (constant and !(length > 0 and std::isfinite(length)))
    c.fail("normal", "must be a non-zero finite vector");
  if (contact.gap.is_constant() and contact.gap(0, 0, 0, 0) < 0)
    c.fail("gap", "must be >= 0");
  contact.friction = read_friction(c);
  c.finish();
  return contact;
}

BoundarySpec read_boundary(Section s, int d)
{
  BoundarySpec b;
  const std::vector<std::string> mechanics_keys = {"clamp", "displacement", "traction", "contact"};
  int count = 0;
  for (const auto& k : mechanics_keys)
    count += s.has(k);
  // A traction may load a contact boundary (the fluid pressure on an open
  // fracture face); otherwise the mechanics conditions exclude each other.
  if (count > 1 and !(count == 2 and s.has("traction") and s.has("contact")))
    s.fail("clamp", "give at most one of clamp, displacement, traction, contact (or traction with contact)");

  if (s.has("clamp"))
  {
    if (!s.boolean("clamp", false))
      s.fail("clamp", "must be true when given");
    b.mechanics = BoundarySpec::Mechanics::displacement;
    for (int i = 0; i < d; ++i)
      b.displacement[i] = Expression(0.0);
  }
  if (s.has("displacement"))
  {
    b.mechanics = BoundarySpec::Mechanics::displacement;
    Section c = s.table("displacement", true);
    const char* names[3] = {"x", "y", "z"};
    for (int i = 0; i < d; ++i)
      b.displacement[i] = c.expression(names[i]);
    c.finish();
    if (!b.displacement[0] and !b.displacement[1] and !b.displacement[2])
      s.fail("displacement", "give at least one component (x, y or z)");
  }
  if (s.has("traction"))
  {
    b.mechanics = BoundarySpec::Mechanics::traction;
    b.traction = s.expression_vector("traction", d);
  }
  if (s.has("contact"))
  {
    b.mechanics = BoundarySpec::Mechanics::contact;
    b.contact = read_contact(s.table("contact", true), d);
  }
  for (const char* key : {"friction", "cohesion", "tresca"})
    if (s.has(key))
      s.fail(key, "acts on a contact: give it in contact = { .., " + std::string(key) + " = .. }");
  b.pore_pressure_load = s.boolean("pore_pressure_load", false);
  if (b.pore_pressure_load and !b.contact)
    s.fail("pore_pressure_load", "loads a contact boundary only (the face of a fracture)");

  if (s.has("pressure") + s.has("flux") + s.has("rate") > 1)
    s.fail(s.has("rate") ? "rate" : "flux", "give at most one of pressure, flux, rate");
  if (auto p = s.expression("pressure"))
  {
    b.flow = BoundarySpec::Flow::pressure;
    b.pressure = *p;
  }
  if (auto f = s.expression("flux"))
  {
    b.flow = BoundarySpec::Flow::flux;
    b.flux = *f;
  }
  if (auto r = s.expression("rate"))
  {
    if (r->depends_on_space())
      s.fail("rate", "the total rate through the boundary depends on t only (use flux for one that varies along it)");
    b.flow = BoundarySpec::Flow::flux;
    b.rate = *r;
  }
  s.finish();
  return b;
}

/// closure = { V_m = .., K_ni = .. }: the Barton-Bandis closure of a
/// conduit fault, whose normal stress the mechanics gives.
ClosureSpec read_closure(Section c)
{
  ClosureSpec closure;
  closure.V_m = c.number("V_m");
  if (!(closure.V_m > 0 and std::isfinite(closure.V_m)))
    c.fail("V_m", "must be a finite number > 0 (m, the largest closure)");
  closure.K_ni = c.number("K_ni");
  if (!(closure.K_ni > 0 and std::isfinite(closure.K_ni)))
    c.fail("K_ni", "must be a finite number > 0 (Pa/m, the initial normal stiffness)");
  c.finish();
  return closure;
}

/// A conduit fault's hydraulic keys (docs/user-guide.md, "Flow in a
/// fault"): its aperture where closed, w_r > 0, the permeability across
/// its faces, k_n > 0 or "inf", its own tangential permeability k_f > 0
/// (else the cubic law), and the closure of its aperture.
void read_conduit(Section& s, const Scene& scene, FaultSpec& f)
{
  if (scene.time_scheme == TimeScheme::bdf2 and scene.coupling
      and (scene.coupling->scheme == CouplingScheme::multirate
           or scene.coupling->scheme == CouplingScheme::multirate_two_pass))
    s.fail("flow", "\"conduit\" with time.scheme = \"bdf2\" and a multirate coupling.scheme: the fault's "
                   "storage is BDF2 in the single-rate schemes only (\"fixed-stress\", \"monolithic\")");
  f.residual_aperture = s.number("residual_aperture");
  if (!(f.residual_aperture > 0 and std::isfinite(f.residual_aperture)))
    s.fail("residual_aperture", "must be a finite number > 0 (m)");
  const toml::node* n = s.node("normal_permeability");
  if (!(n and n->is_string() and n->value<std::string>() == "inf"))
    f.normal_permeability = s.number("normal_permeability", std::numeric_limits<double>::infinity());
  if (!(f.normal_permeability > 0))
    s.fail("normal_permeability", "must be > 0 (m^2) or \"inf\"");
  f.permeability = s.number("permeability", 0.0);
  if (s.has("permeability") and !(f.permeability > 0 and std::isfinite(f.permeability)))
    s.fail("permeability", "must be a finite number > 0 (m^2, the fault's own; without it the cubic law's "
                           "w_h^2 / 12)");
  if (s.has("closure") and !scene.mechanics)
    s.fail("closure", "needs [mechanics]: the closed aperture follows the fault's normal stress");
  if (s.has("closure"))
    f.closure = read_closure(s.table("closure", true));
}

/// fault.NAME: the gap, the fluid pressure in the fault or the pore pressure
/// fault.NAME.tip_size and tip_grading: the mesh graded toward the fault's
/// tips by gmsh, which meshes a .geo only.
void read_tips(Section& s, const Scene& scene, FaultSpec& f)
{
  if (!s.has("tip_size"))
  {
    if (s.has("tip_grading"))
      s.fail("tip_grading", "needs tip_size (the mesh size at the tips)");
    return;
  }
  f.tip_size = s.number("tip_size");
  if (!(f.tip_size > 0 and std::isfinite(f.tip_size)))
    s.fail("tip_size", "must be a finite number > 0 (m)");
  f.tip_grading = s.number("tip_grading", f.tip_grading);
  if (!(f.tip_grading > 0 and std::isfinite(f.tip_grading)))
    s.fail("tip_grading", "must be a finite number > 0 (the size's growth per metre away from the tips)");
  if (std::filesystem::path(scene.mesh.file).extension() != ".geo")
    s.fail("tip_size", "needs a .geo mesh file, which gmsh meshes here (" + scene.mesh.file
                           + " is meshed already: grade its tips in gmsh)");
}

/// beside it, what the fault is to the flow, and the normal's hint.
FaultSpec read_fault(Section s, const Scene& scene)
{
  FaultSpec f;
  f.gap = s.expression("gap").value_or(Expression(0.0));
  if (f.gap.depends_on_time())
    s.fail("gap", "must not depend on t");
  f.pressure = s.expression("pressure");
  f.pore_pressure_load = s.boolean("pore_pressure_load", false);
  if (f.pore_pressure_load and f.pressure)
    s.fail("pore_pressure_load", "give pressure or pore_pressure_load, not both");
  if (f.pore_pressure_load and !scene.flow and !(scene.mechanics and scene.mechanics->pore_pressure))
    s.fail("pore_pressure_load", "needs a pore pressure: [flow], or mechanics.pore_pressure");
  f.flow = s.choice<FaultFlow>("flow", FaultFlow::transparent);
  if (f.flow != FaultFlow::transparent and !scene.flow)
    s.fail("flow", "\"" + std::string(name_of(f.flow)) + "\" in a scene without [flow]");
  if (f.flow == FaultFlow::pressure and !f.pressure)
    s.fail("pressure", "missing (flow = \"pressure\" holds the fault at this pressure)");
  if (f.flow == FaultFlow::conduit)
  {
    // A conduit's faces carry its own fluid pressure p_f: any other pressure
    // on them would be a second, contradictory one.
    if (f.pressure)
      s.fail("pressure", "not with flow = \"conduit\": the fault's own fluid pressure p_f pushes on its faces");
    if (f.pore_pressure_load)
      s.fail("pore_pressure_load", "not with flow = \"conduit\": the fault's own fluid pressure p_f pushes on "
                                   "its faces, not the rock's");
    read_conduit(s, scene, f);
  }
  else if (s.has("permeability") or s.has("normal_permeability"))
    s.fail(s.has("permeability") ? "permeability" : "normal_permeability",
           "only a conduit fault (flow = \"conduit\") has one; this fault is \"" + std::string(name_of(f.flow))
               + "\"");
  const std::size_t d = scene.mesh.dimension;
  f.normal = std::vector<double>(d, 0.0);
  f.normal.back() = 1.0;
  if (s.has("normal"))
    f.normal = s.number_vector("normal", d);
  const double length = std::inner_product(f.normal.begin(), f.normal.end(), f.normal.begin(), 0.0);
  if (!(length > 0 and std::isfinite(length)))
    s.fail("normal", "must be a non-zero finite vector");
  f.friction = read_friction(s);
  read_tips(s, scene, f);
  s.finish();
  return f;
}

} // namespace

void read_boundaries(Section boundaries, Scene& scene)
{
  const int d = scene.mesh.dimension;
  const std::vector<std::string> names = builtin_boundary_names(d);
  for (const std::string& name : boundaries.keys())
  {
    if (scene.mesh.type != MeshType::gmsh and std::find(names.begin(), names.end(), name) == names.end())
    {
      std::string known;
      for (const auto& n : names)
        known += (known.empty() ? "" : ", ") + n;
      boundaries.fail(name,
                      "unknown boundary name (a " + std::string(name_of(scene.mesh.type)) + " has " + known + ")");
    }
    BoundarySpec b = read_boundary(boundaries.table(name, true), d);
    if (!scene.mechanics and b.mechanics != BoundarySpec::Mechanics::traction_free)
      boundaries.fail(name, "mechanics boundary condition in a scene without [mechanics]");
    if (!scene.flow and b.flow != BoundarySpec::Flow::no_flow)
      boundaries.fail(name, "flow boundary condition in a scene without [flow]");
    if (b.pore_pressure_load and !scene.coupling and !(scene.mechanics and scene.mechanics->pore_pressure))
      boundaries.fail(name + ".pore_pressure_load", "needs a pore pressure: a coupled scene, or "
                                                    "mechanics.pore_pressure");
    scene.boundaries[name] = b;
  }
  boundaries.finish();
}

void read_faults(Section faults, Scene& scene)
{
  for (const std::string& name : faults.keys())
  {
    Section s = faults.table(name, true);
    if (scene.mesh.type != MeshType::gmsh)
      faults.fail(name, "a fault is an interior physical group of a gmsh mesh (mesh.type = \"gmsh\")");
    if (scene.boundaries.count(name))
      faults.fail(name, "also given as [boundary." + name + "]: a physical group is a boundary or a fault, "
                        "not both");
    scene.faults[name] = read_fault(s, scene);
  }
  faults.finish();
}

void read_wells(Section wells, Scene& scene)
{
  const int d = scene.mesh.dimension;
  for (const std::string& name : wells.keys())
  {
    Section s = wells.table(name, true);
    if (!scene.flow)
      wells.fail(name, "a well in a scene without [flow]");
    WellSpec w;
    w.position = s.number_vector("position", 2);
    if (d == 3)
    {
      w.bottom = s.number("bottom");
      w.top = s.number("top");
      if (!(w.top > w.bottom))
        s.fail("top", "must be above bottom (the well is the vertical segment from bottom to top)");
    }
    const std::optional<Expression> rate = s.expression("rate");
    if (!rate)
      s.fail("rate", "missing (the volumetric rate, injection positive)");
    if (rate->depends_on_space())
      s.fail("rate", "the rate of a well depends on t only");
    w.rate = *rate;
    w.fault = s.string("fault", "");
    if (!w.fault.empty() and !scene.faults.count(w.fault))
      s.fail("fault", "no fault \"" + w.fault + "\" in the scene ([fault." + w.fault + "])");
    if (!w.fault.empty() and scene.faults.at(w.fault).flow != FaultFlow::conduit)
      s.fail("fault", "fault." + w.fault + " is no conduit (flow = \"conduit\"): a well injects into the rock or a "
                      "conduit fault");
    s.finish();
    scene.wells[name] = w;
  }
  wells.finish();
}

} // namespace biotcontact
