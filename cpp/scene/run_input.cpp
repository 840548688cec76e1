#include "scene/run_input.h"

#include "scene/physics_input.h"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>
#include <string>
#include <vector>

namespace biotcontact
{
namespace
{

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

} // namespace

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

void read_solver(Section solver, int dimension, SolverSpec& choices)
{
  for (auto [key, choice] : {std::pair{"flow", &choices.flow}, std::pair{"mechanics", &choices.mechanics},
                             std::pair{"monolithic", &choices.monolithic}})
    *choice = solver.choice<SolverChoice>(key, SolverChoice::automatic);
  choices.inexact_coupling = solver.boolean("inexact_coupling", true);
  choices.cells_per_rank = solver.integer("cells_per_rank", default_cells_per_rank(dimension));
  if (choices.cells_per_rank < 0)
    solver.fail("cells_per_rank", "must be >= 0 (0: every rank works)");
  solver.finish();
}

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

} // namespace biotcontact
