#include "scene/scene.h"

#include "scene/section.h"


#include <algorithm>
#include <functional>
#include <iomanip>
#include <numeric>
#include <unistd.h>
#include <cmath>
#include <filesystem>
#include <memory>
#include <set>
#include <sstream>
#include <toml++/toml.h>

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
  }
  s.finish();
  return m;
}

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

void positive(Section& s, const std::string& key, double value)
{
  if (!(value > 0) or !std::isfinite(value))
    s.fail(key, "must be a positive finite number");
}

/// mechanics.pore_pressure and its Biot coefficient mechanics.alpha: a
/// pore pressure given as an expression loads the skeleton (one-way
/// coupling); whether the scene may have one is read_physics's to say.
void read_given_pore_pressure(Section& s, MechanicsSpec& m)
{
  m.pore_pressure = s.expression("pore_pressure");
  if (m.pore_pressure and !s.has("alpha"))
    s.fail("alpha", "missing (the Biot coefficient of mechanics.pore_pressure)");
  if (!m.pore_pressure and s.has("alpha"))
    s.fail("alpha", "needs mechanics.pore_pressure (a coupled scene gives coupling.alpha)");
  m.alpha = s.number("alpha", 0.0);
  if (m.pore_pressure and !(m.alpha > 0 and m.alpha <= 1))
    s.fail("alpha", "the Biot coefficient must lie in (0, 1]");
}

MechanicsSpec read_mechanics(Section s, int d)
{
  MechanicsSpec m;
  const bool e_nu = s.has("E") or s.has("nu");
  const bool lame = s.has("G") or s.has("lambda");
  if (e_nu and lame)
    s.fail("E", "give either E and nu, or G and lambda, not both");
  if (!e_nu and !lame)
    s.fail("E", "missing (give E and nu, or G and lambda)");
  if (e_nu)
  {
    const double E = s.number("E");
    const double nu = s.number("nu");
    positive(s, "E", E);
    if (!(nu > -1.0 and nu < 0.5))
      s.fail("nu", "must lie in (-1, 0.5); nu >= 0.5 is an incompressible skeleton");
    m.G = E / (2 * (1 + nu));
    m.lambda = E * nu / ((1 + nu) * (1 - 2 * nu));
  }
  else
  {
    m.G = s.number("G");
    m.lambda = s.number("lambda");
    positive(s, "G", m.G);
    if (!std::isfinite(m.lambda) or m.lambda + 2 * m.G / d <= 0)
      s.fail("lambda", "must be finite with K_dr = lambda + 2G/d > 0");
  }
  if (s.has("body_force"))
    m.body_force = s.expression_vector("body_force", d);
  m.initial_equilibrium = s.boolean("initial_equilibrium", false);
  read_given_pore_pressure(s, m);
  s.finish();
  return m;
}

FlowSpec read_flow(Section s, int d)
{
  FlowSpec f;
  f.M = s.number("M", std::numeric_limits<double>::infinity());
  if (!(f.M > 0))
    s.fail("M", "must be positive (inf for incompressible grains)");
  f.c_f = s.number("c_f", 0.0);
  if (!(f.c_f >= 0) or !std::isfinite(f.c_f))
    s.fail("c_f", "must be >= 0");
  f.phi0 = s.number("phi0", 0.0);
  if (!(f.phi0 >= 0 and f.phi0 <= 1))
    s.fail("phi0", "must lie in [0, 1]");
  f.mu_f = s.number("mu_f");
  positive(s, "mu_f", f.mu_f);

  const toml::node* k = s.node("permeability");
  if (!k)
    s.fail("permeability", "missing");
  if (k->is_array())
  {
    std::vector<double> K;
    for (const toml::node& row : *k->as_array())
    {
      if (!row.is_array() or row.as_array()->size() != static_cast<std::size_t>(d))
        s.fail("permeability", "a tensor must be " + std::to_string(d) + " rows of " + std::to_string(d) + " numbers");
      for (const toml::node& e : *row.as_array())
      {
        if (!e.is_number())
          s.fail("permeability", "tensor entries must be numbers");
        K.push_back(e.value<double>().value());
      }
    }
    if (K.size() != static_cast<std::size_t>(d * d))
      s.fail("permeability", "a tensor must have " + std::to_string(d) + " rows");
    // Symmetric positive definite: symmetric with positive leading minors.
    bool spd = true;
    for (int i = 0; i < d; ++i)
      for (int j = 0; j < d; ++j)
        spd = spd and std::abs(K[i * d + j] - K[j * d + i]) <= 1e-12 * std::abs(K[i * d + i]);
    const double m1 = K[0], m2 = K[0] * K[d + 1] - K[1] * K[d];
    double m3 = 1;
    if (d == 3)
      m3 = K[0] * (K[4] * K[8] - K[5] * K[7]) - K[1] * (K[3] * K[8] - K[5] * K[6])
           + K[2] * (K[3] * K[7] - K[4] * K[6]);
    if (!spd or m1 <= 0 or m2 <= 0 or m3 <= 0)
      s.fail("permeability", "the tensor must be symmetric positive definite");
    f.permeability_tensor = K;
  }
  else
  {
    f.permeability = s.expression(k, "permeability");
    if (f.permeability->is_constant())
      positive(s, "permeability", (*f.permeability)(0, 0, 0, 0));
    if (f.permeability->depends_on_time())
      s.fail("permeability", "must not depend on t");
  }

  if (s.has("gravity") != s.has("rho_f"))
    s.fail(s.has("gravity") ? "rho_f" : "gravity", "gravity needs both rho_f and gravity");
  if (s.has("gravity"))
  {
    f.rho_f = s.number("rho_f");
    positive(s, "rho_f", *f.rho_f);
    f.gravity = s.number_vector("gravity", d);
  }
  f.source = s.expression("source");
  f.initial_pressure = s.expression("initial_pressure").value_or(Expression(0.0));
  if (f.initial_pressure.depends_on_time())
    s.fail("initial_pressure", "must not depend on t");
  s.finish();
  return f;
}

/// coupling.q: a positive integer, or "auto" (time/window_control.h)
/// with the largest q (q_max) and the tolerance of the predicted relative
/// change of the displacement over a window (q_tolerance).
void read_window_steps(Section& s, CouplingSpec& c)
{
  const toml::node* q = s.node("q");
  c.q_auto = q and q->is_string() and q->value<std::string>().value() == "auto";
  c.q = c.q_auto ? 1 : s.integer("q", 1);
  if (c.q < 1)
    s.fail("q", "must be a positive integer or \"auto\"");
  if (!c.multirate() and (c.q != 1 or c.q_auto))
    s.fail("q", std::string(c.q_auto ? "q = \"auto\"" : "q > 1")
                    + " needs scheme = \"multirate\" or \"multirate-two-pass\"");
  if (!c.q_auto)
  {
    for (const char* key : {"q_max", "q_tolerance"})
      if (s.has(key))
        s.fail(key, "needs q = \"auto\"");
    return;
  }
  c.q_max = s.integer("q_max", 16);
  if (c.q_max < 1 or c.q_max > 1024)
    s.fail("q_max", "must be an integer from 1 to 1024");
  c.q_tolerance = s.number("q_tolerance", 1e-2);
  if (!(c.q_tolerance > 0 and c.q_tolerance < 1))
    s.fail("q_tolerance", "must lie in (0, 1)");
}

CouplingSpec read_coupling(Section s, const MechanicsSpec& mech, const FlowSpec& flow)
{
  CouplingSpec c;
  c.alpha = s.number("alpha");
  if (!(c.alpha >= 0 and c.alpha <= 1))
    s.fail("alpha", "the Biot coefficient must lie in [0, 1]");
  c.scheme = s.choice<CouplingScheme>("scheme", CouplingScheme::fixed_stress);
  // The second pass is a flow step without L: with S = 0 its matrix has a
  // zero pressure block, singular wherever no pressure is prescribed.
  if (c.scheme == CouplingScheme::multirate_two_pass and !(flow.storage() > 0))
    s.fail("scheme", "\"multirate-two-pass\" needs a storage coefficient S = 1/M + c_f phi0 > 0");
  read_window_steps(s, c);

  const toml::node* L = s.node("L");
  if (!L)
    c.L_choice = LChoice::paper;
  else if (L->is_number())
  {
    c.L_choice = LChoice::number;
    c.L_number = L->value<double>().value();
    if (!(c.L_number >= 0) or !std::isfinite(c.L_number))
      s.fail("L", "must be >= 0");
  }
  else if (const std::string given = L->value<std::string>().value_or(""); given == "paper")
    c.L_choice = LChoice::paper;
  else if (given == "kdr")
    c.L_choice = LChoice::kdr;
  else if (given == "half-kdr")
    c.L_choice = LChoice::half_kdr;
  else
    s.fail("L", "must be \"paper\", \"kdr\", \"half-kdr\" or a number");
  if (c.L_choice == LChoice::paper and !(mech.lambda > 0))
    s.fail("L", "\"paper\" (alpha^2/lambda) needs lambda > 0; use \"kdr\"");

  c.tolerance = s.number("tolerance", 1e-8);
  if (!(c.tolerance > 0 and c.tolerance < 1))
    s.fail("tolerance", "must lie in (0, 1)");
  c.max_iterations = s.integer("max_iterations", 100);
  if (c.max_iterations < 1)
    s.fail("max_iterations", "must be a positive integer");
  c.acceleration = s.choice<Acceleration>("acceleration", Acceleration::none);
  if (c.acceleration != Acceleration::none and c.scheme == CouplingScheme::monolithic)
    s.fail("acceleration", "accelerates the split; the monolithic scheme has no coupling iteration");
  c.depth = s.integer("depth", 8);
  if (c.depth < 1 or c.depth > 50)
    s.fail("depth", "must be an integer from 1 to 50");
  s.finish();
  return c;
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

/// [mechanics], [flow] and, when both are there, [coupling].
void read_physics(Section& top, Scene& scene)
{
  const int d = scene.mesh.dimension;
  if (top.has("mechanics"))
    scene.mechanics = read_mechanics(top.table("mechanics", true), d);
  if (top.has("flow"))
    scene.flow = read_flow(top.table("flow", true), d);
  if (!scene.mechanics and !scene.flow)
    top.fail("mechanics", "a scene needs a [mechanics] or a [flow] table (or both)");
  if (scene.flow and scene.mechanics and scene.mechanics->pore_pressure)
    top.fail("mechanics.pore_pressure", "a given pore pressure is for a scene without [flow] (here the flow "
                                        "computes it)");
  if (scene.mechanics and scene.flow)
    scene.coupling = read_coupling(top.table("coupling", true), *scene.mechanics, *scene.flow);
  else if (top.has("coupling"))
    top.fail("coupling", "only a scene with both [mechanics] and [flow] is coupled");
}

/// time.adaptive: the tolerance and the bounds of the step (the first step
/// is time.dt).
std::optional<AdaptiveSpec> read_adaptive(Section& time, const Scene& scene)
{
  if (!time.has("adaptive"))
    return std::nullopt;
  Section a = time.table("adaptive", false);
  AdaptiveSpec s;
  s.tolerance = a.number("tolerance");
  if (!(s.tolerance > 0 and s.tolerance < 1))
    a.fail("tolerance", "must lie in (0, 1)");
  s.dt_min = a.number("dt_min", std::min(scene.dt, std::max(scene.dt / 1000, scene.end_time / Scene::max_steps)));
  s.dt_max = a.number("dt_max", scene.end_time);
  if (!(s.dt_min > 0 and s.dt_min <= scene.dt))
    a.fail("dt_min", "must lie in (0, time.dt] (default time.dt / 1000)");
  if (!(s.dt_max >= scene.dt))
    a.fail("dt_max", "must be >= time.dt (default time.end)");
  if (scene.end_time / s.dt_min > Scene::max_steps)
    a.fail("dt_min", "time.end / dt_min is more than the limit of " + std::to_string(Scene::max_steps) + " steps");
  a.finish();
  if (scene.growth > 1.0)
    time.fail("adaptive", "adaptive steps and time.growth exclude each other");
  if (scene.coupling and (scene.coupling->q != 1 or scene.coupling->q_auto))
    time.fail("adaptive", "adaptive steps need q = 1 (coupling.q is "
                              + (scene.coupling->q_auto ? "\"auto\"" : std::to_string(scene.coupling->q)) + ")");
  return s;
}

/// Fixed steps: time.end must be a whole number of at most Scene::max_steps
/// steps dt.
void check_step_count(Section& time, const Scene& scene)
{
  const double steps = scene.end_time / scene.dt;
  // Counted in double precision: an int would overflow silently.
  if (steps > Scene::max_steps)
  {
    std::ostringstream message;
    message << "time.end / time.dt = " << std::setprecision(3) << steps << " steps, more than the limit of "
            << Scene::max_steps;
    time.fail("dt", message.str());
  }
  if (std::abs(steps - std::round(steps)) > 1e-9 * steps or std::round(steps) < 1)
    time.fail("dt", "time.end must be a whole number of steps dt");
}

/// [time]: the end, the first step, its growth or adaptation, the retries
/// and the scheme; fixed steps must be whole, at most Scene::max_steps and,
/// with q > 1, whole windows.
void read_time(Section& top, Scene& scene)
{
  Section time = top.table("time", true);
  scene.end_time = time.number("end");
  scene.dt = time.number("dt");
  positive(time, "dt", scene.dt);
  positive(time, "end", scene.end_time);
  scene.growth = time.number("growth", 1.0);
  scene.retry = time.integer("retry", 0);
  if (scene.retry < 0 or scene.retry > 20)
    time.fail("retry", "must lie in [0, 20] (each retry halves the step)");
  if (!(scene.growth >= 1.0 and scene.growth <= 10.0))
    time.fail("growth", "must lie in [1, 10]");
  scene.time_scheme = time.choice<TimeScheme>("scheme", TimeScheme::backward_euler);
  scene.adaptive = read_adaptive(time, scene);
  if (scene.adaptive)
  {
    time.finish();
    return;
  }
  if (scene.growth == 1.0)
    check_step_count(time, scene);
  if (scene.growth > 1.0 and scene.coupling and (scene.coupling->q != 1 or scene.coupling->q_auto))
    time.fail("growth", "growing time steps need q = 1");
  if (scene.num_steps() > Scene::max_steps)
    time.fail("growth", "more than " + std::to_string(Scene::max_steps) + " time steps");
  time.finish();
  if (scene.coupling and scene.num_steps() % scene.coupling->q != 0)
    top.fail("coupling.q", "the number of fine steps (time.end/time.dt) must be a multiple of q");
}

/// output.times or output.every: the times written, increasing, in
/// (0, time.end], time.end added; with fixed or growing steps each must be
/// the end of a step (of a window for q > 1).
std::vector<double> read_output_times(Section& output, const Scene& scene)
{
  if (output.has("times") and output.has("every"))
    output.fail("every", "give output.times or output.every, not both");
  const double end = scene.end_time, slack = 1e-9 * end;
  std::vector<double> t;
  if (output.has("times"))
  {
    t = output.number_vector("times", 0);
    for (std::size_t i = 0; i < t.size(); ++i)
      if (!(t[i] > 0 and t[i] <= end + slack and (i == 0 or t[i] > t[i - 1] + slack)))
        output.fail("times", "must increase strictly within (0, time.end]");
  }
  else if (output.has("every"))
  {
    const double every = output.number("every");
    if (!(every > 0 and every <= end))
      output.fail("every", "must lie in (0, time.end]");
    for (long k = 1; k * every <= end + slack; ++k)
      t.push_back(k * every);
  }
  else
    return t;
  if (t.empty() or t.back() < end - slack)
    t.push_back(end);
  t.back() = end;
  if (scene.adaptive)
    return t;
  const std::vector<double> run = scene.times();
  const int q = scene.coupling ? scene.coupling->q : 1;
  for (double s : t)
  {
    const auto k = std::lower_bound(run.begin(), run.end(), s - slack) - run.begin();
    if (k == static_cast<long>(run.size()) or std::abs(run[k] - s) > slack or k % q != 0)
    {
      std::ostringstream message;
      message << std::setprecision(6) << s << " is not the end of a " << (q > 1 ? "window" : "step")
              << " of the run (time.dt = " << scene.dt << (q > 1 ? ", q = " + std::to_string(q) : "")
              << "); time.adaptive lands on any time";
      output.fail(output.has("times") ? "times" : "every", message.str());
    }
  }
  return t;
}

/// [output]: XDMF on or off, the times written, the checkpoint interval (in
/// steps) and the progress interval (seconds).
void read_output(Section output, Scene& scene)
{
  scene.write_xdmf = output.boolean("xdmf", true);
  scene.output_times = read_output_times(output, scene);
  scene.checkpoint_every = output.integer("checkpoint_every", 0);
  if (scene.checkpoint_every < 0)
    output.fail("checkpoint_every", "must be >= 0 (0: no checkpoints)");
  scene.progress_interval = output.number("progress_interval", 10.0);
  positive(output, "progress_interval", scene.progress_interval);
  output.finish();
}

/// [solver]: direct, iterative or auto for each system, and inexact coupling.
void read_solver(Section solver, SolverSpec& choices)
{
  for (auto [key, choice] : {std::pair{"flow", &choices.flow}, std::pair{"mechanics", &choices.mechanics},
                             std::pair{"monolithic", &choices.monolithic}})
    *choice = solver.choice<SolverChoice>(key, SolverChoice::automatic);
  choices.inexact_coupling = solver.boolean("inexact_coupling", true);
  solver.finish();
}

/// [well.NAME]: position = [x, y], rate = expr of t; in 3D a vertical
/// segment from bottom to top (z). Whether it lies in the mesh is checked
/// when the domain is made.
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

/// A copy of the scene's table `physics` ([mechanics] or [flow]) with the
/// region's values of `keys` in place of its own; giving one of a pair of
/// moduli drops the other pair from the copy (E, nu replace G, lambda).
toml::table region_physics(const toml::table& root, const std::string& physics, const toml::table& region,
                           const std::vector<std::string>& keys)
{
  toml::table merged = *root.get(physics)->as_table();
  const auto gives = [&](std::initializer_list<const char*> pair)
  { return std::any_of(pair.begin(), pair.end(), [&](const char* k) { return region.contains(k); }); };
  if (gives({"E", "nu"}))
    merged.erase("G"), merged.erase("lambda");
  if (gives({"G", "lambda"}))
    merged.erase("E"), merged.erase("nu");
  for (const std::string& key : keys)
    if (const toml::node* value = region.get(key))
      merged.insert_or_assign(key, *value);
  return merged;
}

/// [region.NAME]: the cells of a gmsh physical group NAME, or those whose
/// midpoint satisfies `where`, with some of the scene's material values
/// replaced. Each region's physics are read by the readers of the scene's
/// own tables, so they are checked alike and errors name region.NAME.KEY.
/// Which cells a region holds is settled when the domain is made.
void read_regions(Section regions, const toml::table& root, Scene& scene)
{
  static const std::vector<std::string> mechanics_keys = {"E", "nu", "G", "lambda", "body_force"};
  static const std::vector<std::string> flow_keys = {"M", "c_f", "phi0", "permeability"};
  const int d = scene.mesh.dimension;
  for (const std::string& name : regions.keys())
  {
    Section s = regions.table(name, true);
    const toml::table& table = *root.get("region")->as_table()->get(name)->as_table();
    for (const std::string& key : s.keys())
    {
      const bool mechanics = std::count(mechanics_keys.begin(), mechanics_keys.end(), key) > 0;
      const bool flow = std::count(flow_keys.begin(), flow_keys.end(), key) > 0;
      if (key == "where" or key == "alpha" or mechanics or flow)
      {
        if ((mechanics and !scene.mechanics) or (flow and !scene.flow) or (key == "alpha" and !scene.coupling))
          s.fail(key, std::string("the scene has no [") + (mechanics ? "mechanics" : flow ? "flow" : "coupling")
                          + "] whose value a region could replace");
        s.node(key);
      }
      else
        s.fail(key, "unknown key (a region may set where, E, nu, G, lambda, body_force, alpha, M, c_f, phi0, "
                    "permeability)");
    }
    RegionSpec r;
    r.where = s.expression("where");
    r.body_force = s.has("body_force");
    if (r.where and (r.where->depends_on_time() or r.where->is_constant()))
      s.fail("where", "must be an expression of x, y, z (the cell midpoints it selects)");
    if (scene.mesh.type != MeshType::gmsh and !r.where)
      s.fail("where", "missing (on a built-in mesh a region is the cells whose midpoint satisfies where)");
    if (scene.mechanics)
    {
      const toml::table merged = region_physics(root, "mechanics", table, mechanics_keys);
      r.mechanics = read_mechanics(regions.derived(&merged, name), d);
    }
    if (scene.flow)
    {
      const toml::table merged = region_physics(root, "flow", table, flow_keys);
      r.flow = read_flow(regions.derived(&merged, name), d);
    }
    if (scene.coupling)
    {
      r.alpha = s.number("alpha", scene.coupling->alpha);
      if (!(r.alpha >= 0 and r.alpha <= 1))
        s.fail("alpha", "the Biot coefficient must lie in [0, 1]");
      if (scene.coupling->L_choice == LChoice::paper and !(r.mechanics->lambda > 0))
        s.fail("lambda", "coupling.L = \"paper\" (alpha^2/lambda) needs lambda > 0; use \"kdr\"");
    }
    else if (r.mechanics)
      r.alpha = r.mechanics->alpha; // mechanics.pore_pressure's, which a region does not replace
    s.finish();
    scene.regions[name] = r;
  }
  regions.finish();
}

/// [boundary.NAME]: built-in meshes know their boundaries' names; a gmsh
/// mesh's are checked against its physical groups when the domain is made.
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
      boundaries.fail(name, "unknown boundary name (a " + std::string(name_of(scene.mesh.type)) + " has " + known + ")");
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
/// its faces, k_n > 0 or "inf", and the closure of its aperture.
void read_conduit(Section& s, const Scene& scene, FaultSpec& f)
{
  if (scene.coupling and scene.coupling->scheme == CouplingScheme::monolithic
      and scene.solver.monolithic == SolverChoice::iterative)
    s.fail("flow", "\"conduit\" with solver.monolithic = \"iterative\": the monolithic system with the fault's "
                   "pressure is solved directly (\"direct\" or \"auto\")");
  if (scene.time_scheme == TimeScheme::bdf2)
    s.fail("flow", "\"conduit\" with time.scheme = \"bdf2\": the fault's storage is backward Euler only yet "
                   "(issue 39)");
  f.residual_aperture = s.number("residual_aperture");
  if (!(f.residual_aperture > 0 and std::isfinite(f.residual_aperture)))
    s.fail("residual_aperture", "must be a finite number > 0 (m)");
  const toml::node* n = s.node("normal_permeability");
  if (!(n and n->is_string() and n->value<std::string>() == "inf"))
    f.normal_permeability = s.number("normal_permeability", std::numeric_limits<double>::infinity());
  if (!(f.normal_permeability > 0))
    s.fail("normal_permeability", "must be > 0 (m^2) or \"inf\"");
  if (s.has("closure") and !scene.mechanics)
    s.fail("closure", "needs [mechanics]: the closed aperture follows the fault's normal stress");
  if (s.has("closure"))
    f.closure = read_closure(s.table("closure", true));
}

/// fault.NAME: the gap, the fluid pressure in the fault or the pore pressure
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
  const std::size_t d = scene.mesh.dimension;
  f.normal = std::vector<double>(d, 0.0);
  f.normal.back() = 1.0;
  if (s.has("normal"))
    f.normal = s.number_vector("normal", d);
  const double length = std::inner_product(f.normal.begin(), f.normal.end(), f.normal.begin(), 0.0);
  if (!(length > 0 and std::isfinite(length)))
    s.fail("normal", "must be a non-zero finite vector");
  f.friction = read_friction(s);
  s.finish();
  return f;
}

/// [fault.NAME]: faults lie inside a gmsh mesh, on groups that are not
/// boundaries. That NAME is an interior group of the mesh, and the gap
/// >= 0 at its nodes, are checked where the mesh is split along it.
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

/// Mandel's rigid frictionless plate goes on the boundary `ref.plate`,
/// which must be free: set-up imposes the exact u_y there
/// (diagnostics/closed_form.h, with_mandel_plate).
void check_mandel_plate(Section& r, const Scene& scene, const ReferenceSpec& ref)
{
  if (scene.mesh.lower[0] != 0.0 or scene.mesh.lower[1] != 0.0)
    r.fail("solution", "mandel needs mesh.lower = [0, 0] (the quarter specimen)");
  auto it = scene.boundaries.find(ref.plate);
  if (it == scene.boundaries.end() or it->second.mechanics != BoundarySpec::Mechanics::traction_free)
    r.fail("plate", "must name a boundary with no mechanics condition of its own");
}

/// [reference]: the closed form the run is compared with ("none" switches
/// the comparison of a reference scene off, e.g. from --set).
void read_reference(Section r, Scene& scene)
{
  ReferenceSpec ref;
  const std::string solution = r.string("solution");
  if (solution != "terzaghi" and solution != "mandel" and solution != "none")
    r.fail("solution", "must be \"terzaghi\", \"mandel\" or \"none\"");
  if (solution == "none")
  {
    for (const std::string& key : r.keys())
      r.node(key);
    r.finish();
    return;
  }
  ref.solution = solution == "terzaghi" ? ReferenceSolution::terzaghi : ReferenceSolution::mandel;
  if (!scene.coupling or scene.mesh.type != MeshType::rectangle)
    r.fail("solution", solution + " needs a coupled scene on a rectangle");
  if (!scene.flow->permeability or !scene.flow->permeability->is_constant())
    r.fail("solution", solution + " needs a constant scalar flow.permeability");
  if (!scene.regions.empty())
    r.fail("solution", solution + " is the closed form of a homogeneous medium: the scene has regions");
  if (ref.solution == ReferenceSolution::terzaghi)
  {
    ref.load = r.number("load");
    ref.height = scene.mesh.upper[1] - scene.mesh.lower[1];
  }
  else
  {
    ref.force = r.number("force");
    ref.plate = r.string("plate", "top");
    check_mandel_plate(r, scene, ref);
  }
  r.finish();
  scene.reference = ref;
}

} // namespace

std::vector<std::string> builtin_boundary_names(int dimension)
{
  if (dimension == 2)
    return {"left", "right", "bottom", "top"};
  return {"left", "right", "front", "back", "bottom", "top"};
}

bool Scene::cellwise_body_force() const
{
  return std::any_of(regions.begin(), regions.end(), [](const auto& entry) { return entry.second.body_force; });
}

bool Scene::has_contact() const
{
  for (const auto& [name, b] : boundaries)
    if (b.contact)
      return true;
  return !faults.empty();
}

std::vector<double> Scene::times() const
{
  std::vector<double> t = {0.0};
  if (growth == 1.0)
  {
    // Whole multiples of dt, so that every scheme writes the same times.
    const long n = std::llround(end_time / dt);
    for (long k = 1; k <= n; ++k)
      t.push_back(k * dt);
    return t;
  }
  // dt_k = dt growth^(k-1); the last step ends at time.end.
  double step = dt;
  // Stops one past the limit, which read_scene then refuses.
  while (t.back() < end_time * (1 - 1e-12) and t.size() <= static_cast<std::size_t>(max_steps) + 1)
  {
    t.push_back(std::min(t.back() + step, end_time));
    step *= growth;
  }
  return t;
}

int Scene::num_steps() const
{
  if (growth == 1.0)
    return static_cast<int>(std::llround(end_time / dt));
  return static_cast<int>(times().size()) - 1;
}

std::vector<double> Scene::stops() const
{
  return output_times.empty() ? std::vector<double>{end_time} : output_times;
}

bool Scene::is_output_time(double t) const
{
  if (output_times.empty())
    return true;
  const auto k = std::lower_bound(output_times.begin(), output_times.end(), t - 1e-9 * end_time);
  return k != output_times.end() and std::abs(*k - t) <= 1e-9 * end_time;
}

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
  read_solver(top.table("solver", false), scene.solver);
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
