#include "scene/physics_input.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

namespace biotcontact
{
namespace
{

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
  c.acceleration = s.choice<Acceleration>("acceleration", Acceleration::automatic);
  if (c.acceleration == Acceleration::anderson and c.scheme == CouplingScheme::monolithic)
    s.fail("acceleration", "accelerates the split; the monolithic scheme has no coupling iteration");
  c.depth = s.integer("depth", 8);
  if (c.depth < 1 or c.depth > 50)
    s.fail("depth", "must be an integer from 1 to 50");
  c.fallback = s.choice<Fallback>("fallback", Fallback::none);
  if (c.fallback == Fallback::monolithic and c.scheme == CouplingScheme::monolithic)
    s.fail("fallback", "takes over a step the split fails at; the monolithic scheme has no split");
  c.pin_cycles = s.boolean("pin_cycles", true);
  s.finish();
  return c;
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

} // namespace

void positive(Section& s, const std::string& key, double value)
{
  if (!(value > 0) or !std::isfinite(value))
    s.fail(key, "must be a positive finite number");
}

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

} // namespace biotcontact
