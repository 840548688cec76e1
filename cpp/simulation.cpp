#include "simulation.h"

#include "diagnostics/closed_form.h"
#include "diagnostics/diagnostics.h"
#include "domain/domain.h"
#include "coupling/fixed_stress.h"
#include "steps/flow_step.h"
#include "assembly/forms.h"
#include "steps/mechanics_step.h"
#include "steps/monolithic_step.h"
#include "output/checkpoint.h"
#include "output/interruption.h"
#include "output/output.h"
#include "assembly/parameters.h"

#include <basix/finite-element.h>
#include <chrono>
#include <cmath>
#include <sstream>
#include <cstdio>
#include <dolfinx/fem/utils.h>
#include <functional>
#include <optional>
#include <tuple>
#include <xtensor/xarray.hpp>

namespace biotcontact
{
using namespace dolfinx;

namespace
{

bool rank0(MPI_Comm comm)
{
  int r = 0;
  MPI_Comm_rank(comm, &r);
  return r == 0;
}

std::int64_t global_size(const fem::FunctionSpace& V)
{
  return V.dofmap()->index_map->size_global() * V.dofmap()->index_map_bs();
}

/// Mean vertical displacement of the nodes of one boundary (collective).
double boundary_mean(const fem::Function<double>& u, const std::vector<std::int32_t>& facets, int component)
{
  const auto& V = *u.function_space();
  const auto dofs = fem::locate_dofs_topological(*V.sub({component}), V.mesh()->topology().dim() - 1, facets);
  const std::int32_t owned = owned_size(V);
  double local[2] = {0, 0};
  for (std::int32_t dof : dofs)
    if (dof < owned)
    {
      local[0] += u.x()->array()[dof];
      local[1] += 1;
    }
  double global[2];
  MPI_Allreduce(local, global, 2, MPI_DOUBLE, MPI_SUM, V.mesh()->comm());
  return global[0] / global[1];
}

Json contact_json(const ContactState& c)
{
  Json j;
  j.set("contact_nodes", c.contact_nodes)
      .set("active_nodes", c.active_nodes)
      .set("max_penetration", c.max_penetration)
      .set("max_complementarity", c.max_complementarity)
      .set("max_contact_pressure", c.max_pressure)
      .set("min_contact_pressure", c.min_pressure)
      .set("gap_scale", c.gap_scale)
      .set("total_force", c.total_force);
  return j;
}

/// The relative L2 errors (and Terzaghi's settlement) at the final time
/// against the scene's closed form, Terzaghi or Mandel.
Json closed_form_errors(const Scene& scene, const Parameters& P, const Domain& domain, const CompiledForms& forms,
                        std::shared_ptr<fem::Function<double>> u, std::shared_ptr<fem::Function<double>> p)
{
  const int d = domain.dim();
  Json errors;
  const ReferenceSpec& ref = *scene.reference;
  const FlowSpec& fs = *scene.flow;
  const double mobility = (*fs.permeability)(0, 0, 0, 0) / fs.mu_f;
  const double t = scene.end_time, y0 = scene.mesh.lower[1];
  // The closed form: pressure and displacement at a point (x, y).
  std::function<double(double, double)> p_exact;
  std::function<std::array<double, 2>(double, double)> u_exact;
  std::optional<Terzaghi> terzaghi;
  std::optional<Mandel> mandel;
  if (ref.solution == "terzaghi")
  {
    terzaghi.emplace(Terzaghi{ref.height, P.G, P.lambda, P.alpha, P.storage, mobility, ref.load});
    p_exact = [&](double, double y) { return terzaghi->pressure(y - y0, t); };
    u_exact = [&](double, double y) { return std::array<double, 2>{0.0, terzaghi->displacement(y - y0, t)}; };
  }
  else
  {
    mandel.emplace(scene.mesh.upper[0], scene.mesh.upper[1], P.G, P.lambda, P.alpha, P.storage, mobility,
                   ref.force);
    p_exact = [&](double x, double) { return mandel->pressure(x, t); };
    u_exact = [&](double x, double y)
    { return std::array<double, 2>{mandel->displacement_x(x, t), mandel->displacement_y(y, t)}; };
  }
  auto p_ref = std::make_shared<fem::Function<double>>(std::make_shared<fem::FunctionSpace>(
      fem::create_functionspace(forms.pressure_reference_space, "p_reference", domain.mesh)));
  auto u_ref = std::make_shared<fem::Function<double>>(std::make_shared<fem::FunctionSpace>(
      fem::create_functionspace(forms.displacement_reference_space, "u_reference", domain.mesh)));
  p_ref->interpolate(
      [&](const xt::xtensor<double, 2>& x) -> xt::xarray<double>
      {
        xt::xarray<double> v = xt::zeros<double>({x.shape(1)});
        for (std::size_t j = 0; j < x.shape(1); ++j)
          v(j) = p_exact(x(0, j), x(1, j));
        return v;
      });
  u_ref->interpolate(
      [&](const xt::xtensor<double, 2>& x) -> xt::xarray<double>
      {
        xt::xarray<double> v = xt::zeros<double>({std::size_t(d), x.shape(1)});
        for (std::size_t j = 0; j < x.shape(1); ++j)
        {
          const auto uj = u_exact(x(0, j), x(1, j));
          v(0, j) = uj[0];
          v(1, j) = uj[1];
        }
        return v;
      });
  errors.set("time", t)
      .set("pressure_rel_l2", relative_error(*forms.M_pressure_error, *forms.M_pressure_reference,
                                             p, "p_out", p_ref, "p_reference"))
      .set("displacement_rel_l2",
           relative_error(*forms.M_displacement_error, *forms.M_displacement_reference,
                          u, "u_out", u_ref, "u_reference"));
  if (terzaghi)
  {
    const double settlement = -boundary_mean(*u, domain.boundaries.at("top"), 1);
    const double exact_settlement = terzaghi->settlement(t);
    errors.set("settlement", settlement)
        .set("settlement_exact", exact_settlement)
        .set("settlement_rel", std::abs(settlement - exact_settlement) / std::abs(exact_settlement));
  }
  return errors;
}

/// The unknowns at the start of a step, to go back to when it is retried.
struct StepState
{
  std::vector<double> flow, displacement, monolithic;
};

StepState step_state(const FlowStep* flow, const MechanicsStep* mechanics, const MonolithicStep* coupled)
{
  auto copy = [](std::span<const double> x) { return std::vector<double>(x.begin(), x.end()); };
  return {flow ? copy(flow->state()) : std::vector<double>{},
          mechanics ? copy(mechanics->u->x()->array()) : std::vector<double>{},
          coupled ? copy(coupled->state()) : std::vector<double>{}};
}

void set_step_state(const StepState& s, FlowStep* flow, MechanicsStep* mechanics, MonolithicStep* coupled)
{
  if (flow)
    flow->set_state(s.flow);
  if (mechanics)
    std::copy(s.displacement.begin(), s.displacement.end(), mechanics->u->x()->mutable_array().begin());
  if (coupled)
    coupled->set_state(s.monolithic);
}

/// mechanics.initial_equilibrium: replaces u = 0 by the displacement in
/// equilibrium with the loads at t = 0 and the initial pressure (a geostatic
/// initialisation). Otherwise loads present from the start, such as the
/// in-situ stresses, are applied in the first step as a sudden load, whose
/// undrained pressure response the first flow steps then carry.
void equilibrate(const Scene& scene, const Domain& domain, const CompiledForms& forms,
                 const Constants& constants, MechanicsStep* mechanics, MonolithicStep* coupled)
{
  if (mechanics)
  {
    mechanics->solve(0.0);
    return;
  }
  // The coupled system has no mechanics system of its own: one mechanics
  // step on its displacement space, loaded by its pressure, solved once.
  MechanicsStep step(scene, domain, forms, constants, coupled->V, coupled->pressure);
  step.solve(0.0);
  coupled->set_displacement(step.u->x()->array(), 0.0);
}

/// The state a restart needs after `steps` completed steps (checkpoint.h).
Checkpoint capture_state(int steps, double time, const FlowStep* flow, const MechanicsStep* mechanics,
                         const MonolithicStep* coupled, const CouplingReport& report,
                         const std::array<System*, 4>& systems, const std::string& output, const TimeGrid& grid)
{
  Checkpoint c;
  c.steps = steps;
  c.time = time;
  auto keep = [&](const std::string& name, std::span<const double> x) { c.arrays[name].assign(x.begin(), x.end()); };
  // The grid as retries left it (the same on every rank).
  keep("times", grid.t);
  keep("time_steps", grid.dt);
  if (flow)
    keep("flow", flow->state());
  if (mechanics)
    keep("displacement", mechanics->u->x()->array());
  if (coupled)
    keep("monolithic", coupled->state());
  c.numbers = {{"windows", report.windows},
               {"coupling_iterations", report.coupling_iterations},
               {"max_iterations_per_step", report.max_iterations_per_step},
               {"max_contraction_ratio", report.max_contraction_ratio},
               {"ratios", report.ratios},
               {"bound_violations", report.bound_violations},
               {"unresolved_ratios", report.unresolved_ratios},
               {"max_coupled_residual", report.max_coupled_residual},
               {"ratio_sum", report.ratio_sum},
               {"p_size", report.p_size},
               {"u_size", report.u_size},
               {"retries", report.retries}};
  for (std::size_t i = 0; i < systems.size(); ++i)
  {
    if (!systems[i])
      continue;
    const SolverStatistics s = systems[i]->statistics();
    const std::string k = std::to_string(i) + ".";
    c.numbers[k + "solves"] = s.solves;
    c.numbers[k + "setups"] = s.setups;
    c.numbers[k + "back_solves"] = s.back_solves;
    c.numbers[k + "linear_iterations"] = s.linear_iterations;
    c.numbers[k + "newton_iterations"] = s.newton_iterations;
    c.numbers[k + "active_set_changes"] = s.active_set_changes;
    c.numbers[k + "schur_columns"] = s.schur_columns;
  }
  c.output = output;
  return c;
}

/// Loads a checkpoint into the steps, the report and the solver counts.
void restore_state(const Checkpoint& c, FlowStep* flow, MechanicsStep* mechanics, MonolithicStep* coupled,
                   CouplingReport& report, const std::array<System*, 4>& systems, TimeGrid& grid)
{
  grid.t = c.arrays.at("times");
  grid.dt = c.arrays.at("time_steps");
  if (flow)
    flow->set_state(c.arrays.at("flow"));
  if (mechanics)
  {
    const std::vector<double>& u = c.arrays.at("displacement");
    std::copy(u.begin(), u.end(), mechanics->u->x()->mutable_array().begin());
  }
  if (coupled)
    coupled->set_state(c.arrays.at("monolithic"));
  auto n = [&](const std::string& k) { return c.numbers.at(k); };
  report.windows = static_cast<int>(n("windows"));
  report.coupling_iterations = static_cast<long>(n("coupling_iterations"));
  report.max_iterations_per_step = static_cast<int>(n("max_iterations_per_step"));
  report.max_contraction_ratio = n("max_contraction_ratio");
  report.ratios = static_cast<long>(n("ratios"));
  report.bound_violations = static_cast<long>(n("bound_violations"));
  report.unresolved_ratios = static_cast<long>(n("unresolved_ratios"));
  report.max_coupled_residual = n("max_coupled_residual");
  report.ratio_sum = n("ratio_sum");
  report.retries = static_cast<long>(n("retries"));
  report.p_size = n("p_size");
  report.u_size = n("u_size");
  for (std::size_t i = 0; i < systems.size(); ++i)
  {
    if (!systems[i])
      continue;
    const std::string k = std::to_string(i) + ".";
    SolverStatistics s;
    s.solves = static_cast<long>(n(k + "solves"));
    s.setups = static_cast<long>(n(k + "setups"));
    s.back_solves = static_cast<long>(n(k + "back_solves"));
    s.linear_iterations = static_cast<long>(n(k + "linear_iterations"));
    s.newton_iterations = static_cast<long>(n(k + "newton_iterations"));
    s.active_set_changes = static_cast<long>(n(k + "active_set_changes"));
    s.schur_columns = static_cast<long>(n(k + "schur_columns"));
    systems[i]->add_earlier(s);
  }
}

} // namespace

int run(const Scene& scene, const std::string& directory, MPI_Comm comm, const RunControl& control)
{
  const auto start = std::chrono::steady_clock::now();
  const bool root = rank0(comm);
  auto say = [&](const std::string& s)
  {
    if (root)
      std::printf("%s\n", s.c_str()), std::fflush(stdout);
  };

  // ---- scene -> mesh and tags -> forms ------------------------------------
  const Domain domain = create_domain(scene, comm);
  check_expressions(scene, domain, comm);
  const CompiledForms& forms = compiled_forms(domain.mesh->topology().cell_type());
  const Parameters P = derive_parameters(scene);
  const Constants constants = make_constants(scene, P);
  const int d = domain.dim();

  // Each scene allocates only the physics it has.
  std::string left_out;
  auto leave_out = [&](const std::string& what) { left_out += (left_out.empty() ? "" : "; ") + what; };
  if (!scene.flow)
    leave_out("flow (no [flow] table): no flux or pressure unknowns");
  if (!scene.mechanics)
    leave_out("mechanics (no [mechanics] table): no displacement unknowns");
  if (scene.mechanics and !scene.has_contact())
    leave_out("contact solver (no contact boundary): linear mechanics solve");
  if (scene.flow and !scene.flow->gravity)
    leave_out("gravity");
  if (scene.mechanics and !scene.mechanics->body_force)
    leave_out("body force");
  say("biotcontact: scene " + scene.name + " (" + scene.file + "), " + std::to_string(d) + "D, "
      + std::to_string(domain.mesh->topology().index_map(d)->size_global()) + " cells");
  say("left out: " + (left_out.empty() ? std::string("nothing") : left_out));

  // Where the method is known to degrade, the run says so instead of
  // returning poor numbers silently (docs/stability.md has the data).
  std::string warnings;
  auto warn = [&](const std::string& what)
  {
    warnings += (warnings.empty() ? "" : "; ") + what;
    say("warning: " + what);
  };
  if (scene.mechanics)
  {
    const double nu = P.lambda / (2 * (P.lambda + P.G));
    if (nu > 0.49)
      warn("nu = " + std::to_string(nu) + " > 0.49: P1 displacements lock as nu -> 0.5 "
           "(too stiff a response, worse on coarse meshes)");
  }
  if (scene.coupling and scene.coupling->scheme != "monolithic" and P.gamma > 0.99)
    warn("gamma = " + std::to_string(P.gamma) + " > 0.99: the contraction theorems guarantee almost "
         "nothing, expect many coupling iterations or none converging (monolithic is the robust choice)");

  // ---- flow step / mechanics step, or the monolithic system ----------------
  const bool monolithic = scene.coupling and scene.coupling->scheme == "monolithic";
  std::unique_ptr<FlowStep> flow, second_pass;
  std::unique_ptr<MechanicsStep> mechanics;
  std::unique_ptr<MonolithicStep> coupled;
  // What output and diagnostics read, whichever solver produced it.
  std::shared_ptr<const fem::FunctionSpace> V;
  std::shared_ptr<fem::Function<double>> u, p, contact_pressure, contact_active, contact_boundary;
  std::function<void(fem::Function<double>&)> compute_flux;
  std::function<ContactState()> compute_contact = [] { return ContactState{}; };
  if (monolithic)
  {
    coupled = std::make_unique<MonolithicStep>(scene, domain, forms, constants);
    V = coupled->V;
    u = coupled->u;
    p = coupled->pressure;
    compute_flux = [&](fem::Function<double>& out) { coupled->flux(out); };
    if (coupled->has_contact())
    {
      contact_pressure = coupled->contact_pressure;
      contact_active = coupled->contact_active;
      contact_boundary = coupled->contact_boundary;
      compute_contact = [&] { return coupled->contact_state(); };
    }
  }
  else
  {
    if (scene.mechanics)
      V = std::make_shared<fem::FunctionSpace>(fem::create_functionspace(forms.displacement_space, "u", domain.mesh));
    if (scene.flow)
    {
      flow = std::make_unique<FlowStep>(scene, domain, forms, constants, scene.coupling ? V : nullptr);
      p = flow->pressure;
      if (scene.coupling and scene.coupling->scheme == "multirate-two-pass")
      {
        // The second pass is the flow step without the stabilisation L.
        Constants unstabilised = constants;
        unstabilised["L"] = std::make_shared<const fem::Constant<double>>(0.0);
        second_pass = std::make_unique<FlowStep>(scene, domain, forms, unstabilised, V);
      }
      compute_flux = [&](fem::Function<double>& out) { flow->flux(out); };
    }
    if (scene.mechanics)
    {
      mechanics = std::make_unique<MechanicsStep>(scene, domain, forms, constants, V, p);
      u = mechanics->u;
      if (mechanics->has_contact())
      {
        contact_pressure = mechanics->contact_pressure;
        contact_active = mechanics->contact_active;
        contact_boundary = mechanics->contact_boundary;
        compute_contact = [&] { return mechanics->contact_state(); };
      }
    }
  }

  // ---- output fields ---------------------------------------------------------
  std::optional<Checkpoint> resumed;
  if (control.restart)
    resumed = read_checkpoint(comm, directory, control.fingerprint);
  Output output(comm, directory, domain.mesh, scene.write_xdmf, resumed ? &resumed->output : nullptr);
  const auto cell = mesh::cell_type_to_basix_type(domain.mesh->topology().cell_type());
  const basix::FiniteElement dg0 = basix::create_element(
      basix::element::family::P, cell, 0, basix::element::lagrange_variant::unset, true);
  std::shared_ptr<fem::Function<double>> flux, sigma_v, zero_pressure;
  if (p)
  {
    p->name = "pressure";
    flux = std::make_shared<fem::Function<double>>(
        std::make_shared<fem::FunctionSpace>(fem::create_functionspace(domain.mesh, dg0, d)));
    flux->name = "flux";
  }
  if (u)
  {
    u->name = "displacement";
    auto Q0 = std::make_shared<fem::FunctionSpace>(fem::create_functionspace(domain.mesh, dg0, 1));
    sigma_v = std::make_shared<fem::Function<double>>(Q0);
    sigma_v->name = "sigma_v";
    if (!p)
      zero_pressure = std::make_shared<fem::Function<double>>(Q0);
    if (contact_pressure)
    {
      contact_pressure->name = "contact_pressure";
      contact_active->name = "contact_active";
    }
  }
  auto write_flow = [&](double t)
  {
    output.write(*p, t);
    compute_flux(*flux);
    output.write(*flux, t);
  };
  ContactState contact;
  auto write_mechanics = [&](double t)
  {
    contact = compute_contact(); // also fills the contact fields
    volumetric_stress(forms, constants, u, p ? p : zero_pressure, *sigma_v);
    output.write(*u, t);
    output.write(*sigma_v, t);
    if (contact_pressure)
    {
      output.write(*contact_pressure, t);
      output.write(*contact_active, t);
    }
  };
  // The time steps; a retry (time.retry) halves some of them.
  TimeGrid grid = time_grid(scene);
  char line[256];
  int completed_steps = 0; // mechanics steps (windows) written
  double completed_time = 0;
  auto progress = [&](int step, double t, int iterations)
  {
    completed_steps = step;
    completed_time = t;
    std::snprintf(line, sizeof line, "step %4d/%d  t = %-11.5g  coupling iterations %3d  active contact nodes %d",
                  step, grid.steps() / P.q, t, iterations, contact.active_nodes);
    say(line);
  };

  // ---- initial state, or the state of the checkpoint ----------------------------
  CouplingReport report;
  std::array<System*, 4> systems = {flow ? &flow->system() : nullptr, mechanics ? &mechanics->system() : nullptr,
                                     coupled ? &coupled->system() : nullptr,
                                     second_pass ? &second_pass->system() : nullptr};
  if (resumed)
  {
    restore_state(*resumed, flow.get(), mechanics.get(), coupled.get(), report, systems, grid);
    completed_steps = resumed->steps;
    completed_time = resumed->time;
    if (u)
      contact = compute_contact();
    say("restarted from the checkpoint at step " + std::to_string(completed_steps) + ", t = "
        + std::to_string(completed_time));
  }
  else
  {
    if (scene.mechanics and scene.mechanics->initial_equilibrium)
      equilibrate(scene, domain, forms, constants, mechanics.get(), coupled.get());
    if (p)
      write_flow(0.0);
    if (u)
      write_mechanics(0.0);
    if (contact_boundary)
      output.write(*contact_boundary, 0.0); // once: every later time repeats it
  }

  // ---- time stepping -----------------------------------------------------------
  std::string failure;
  int signal = 0;
  // After each completed (and written) step: a checkpoint every
  // checkpoint_every steps and at an interruption; then whether to stop.
  int saved = resumed ? completed_steps : 0;
  auto save = [&]
  {
    write_checkpoint(comm, directory, control.fingerprint,
                     capture_state(completed_steps, completed_time, flow.get(), mechanics.get(), coupled.get(),
                                   report, systems, output.state(), grid));
    saved = completed_steps;
  };
  auto stop = [&]
  {
    if (scene.checkpoint_every > 0 and completed_steps % scene.checkpoint_every == 0)
      save();
    signal = interruption_signal(comm);
    if (signal and scene.checkpoint_every > 0 and saved != completed_steps)
      save();
    return signal != 0;
  };
  // A solve that fails names the step it was computing.
  auto at_failing_step = [&](const std::string& cause)
  {
    const int step = completed_steps + 1;
    std::ostringstream s;
    s << "step " << step << " (t = " << grid.t[std::min<std::size_t>(step * P.q, grid.t.size() - 1)]
      << "): " << cause;
    return s.str();
  };
  try
  {
    if (scene.coupling and !monolithic)
    {
      ContractionNorm contraction(forms, V, flow->pressure_space());
      WindowObserver observer{write_flow,
                              [&](double t, int window, int iterations)
                              {
                                write_mechanics(t);
                                progress(window, t, iterations);
                              },
                              stop, say};
      run_fixed_stress(scene, P, constants, *flow, second_pass.get(), *mechanics, contraction, output, observer,
                       report, grid);
    }
    else
    {
      // One solve per step: the monolithic system, or the single physics.
      int attempts = 0; // retries of the current step (time.retry)
      for (int k = report.windows + 1; k <= grid.steps(); ++k)
      {
        const double t = grid.t[k];
        if (set_time_step(constants, grid.dt[k - 1]))
        {
          if (coupled)
            coupled->time_step_changed();
          if (flow)
            flow->time_step_changed();
        }
        const StepState at_step_start = step_state(flow.get(), mechanics.get(), coupled.get());
        try
        {
          if (coupled)
            coupled->solve(t);
          if (flow)
          {
            std::copy(p->x()->array().begin(), p->x()->array().end(),
                      flow->p_previous->x()->mutable_array().begin());
            flow->solve(t);
          }
          if (mechanics)
            mechanics->solve(t);
        }
        catch (const SolverError& e)
        {
          // time.retry: back to the start of the step, halved.
          const auto message = retry_step(scene, e.what(), k, attempts, grid, k - 1, 1, report.retries);
          if (!message)
            throw;
          say(*message);
          set_step_state(at_step_start, flow.get(), mechanics.get(), coupled.get());
          --k;
          continue;
        }
        attempts = 0;
        if (p)
          write_flow(t);
        if (u)
          write_mechanics(t);
        progress(k, t, 1);
        report.windows = k;
        if (stop())
          break;
      }
    }
  }
  catch (const CouplingError& e)
  {
    failure = e.what(); // names its step and the last increments
  }
  catch (const SolverError& e)
  {
    failure = at_failing_step(e.what());
    report.windows = completed_steps;
  }
  contact = compute_contact();

  // ---- errors against a closed form at the final time --------------------------
  const bool has_errors = scene.reference and failure.empty() and signal == 0;
  const Json errors = has_errors ? closed_form_errors(scene, P, domain, forms, u, p) : Json();

  // ---- summary ------------------------------------------------------------------
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  Json dofs, timings, linear;
  if (u)
    dofs.set("displacement", static_cast<long>(global_size(*V)));
  if (p)
  {
    dofs.set("pressure", static_cast<long>(global_size(*p->function_space())));
    // RT0: one DOF per facet.
    dofs.set("flux", static_cast<long>(domain.mesh->topology().index_map(d - 1)->size_global()));
  }
  // Per system: what solved it, how often it was set up (factorised) and
  // solved, and where its time went.
  const System* flow_system = flow ? &flow->system() : nullptr;
  const System* mechanics_system = mechanics ? &mechanics->system() : nullptr;
  const System* coupled_system = coupled ? &coupled->system() : nullptr;
  const System* second_pass_system = second_pass ? &second_pass->system() : nullptr;
  SolverStatistics none;
  auto statistics = [&](const System* s) { return s ? s->statistics() : none; };
  const SolverStatistics flow_stats = statistics(flow_system), mechanics_stats = statistics(mechanics_system),
                         coupled_stats = statistics(coupled_system),
                         second_pass_stats = statistics(second_pass_system);
  Json solvers;
  for (const auto& [name, system, st] : {std::tuple{"flow", flow_system, flow_stats},
                                         std::tuple{"mechanics", mechanics_system, mechanics_stats},
                                         std::tuple{"monolithic", coupled_system, coupled_stats},
                                         std::tuple{"flow_second_pass", second_pass_system, second_pass_stats}})
  {
    if (!system)
      continue;
    Json j;
    const bool direct = system->method() == Method::direct;
    j.set("solver", method_name(system->method()))
        .set("method", system->description())
        .set("unknowns", system->unknowns())
        .set("solves", st.solves)
        .set("factorizations", direct ? st.setups : 0)
        .set("preconditioner_setups", st.setups)
        .set("inexact_coupling", !direct and system != coupled_system and scene.solver.inexact_coupling)
        .set("back_solves", st.back_solves)
        .set("linear_iterations", st.linear_iterations);
    if (system->has_contact())
      j.set("newton_iterations", st.newton_iterations)
          .set("active_set_changes", st.active_set_changes)
          .set("schur_columns", st.schur_columns);
    solvers.set(name, j);
    Json t;
    t.set("total", st.total_time)
        .set("setup", st.setup_time)
        .set("solve", st.solve_time)
        .set("schur_complement", st.schur_time)
        .set("other", st.total_time - st.setup_time - st.solve_time - st.schur_time)
        .set("matrix_assembly", st.assembly_time);
    timings.set(name, t);
  }
  linear.set("flow", flow_stats.linear_iterations + second_pass_stats.linear_iterations)
      .set("mechanics", mechanics_stats.linear_iterations)
      .set("monolithic", coupled_stats.linear_iterations);
  timings
      .set("assembly", (flow ? flow->assembly_time : 0.0) + (mechanics ? mechanics->assembly_time : 0.0)
                           + (coupled ? coupled->assembly_time : 0.0)
                           + (second_pass ? second_pass->assembly_time : 0.0) + flow_stats.assembly_time
                           + mechanics_stats.assembly_time + coupled_stats.assembly_time
                           + second_pass_stats.assembly_time)
      .set("output", output.time);

  Json summary;
  summary.set("scene", scene.name)
      .set("scheme", scene.coupling ? scene.coupling->scheme : (flow ? "flow-only" : "mechanics-only"))
      .set("q", P.q)
      .set("L_choice", scene.coupling ? scene.coupling->L_choice : "none")
      .set("acceleration", scene.coupling and scene.coupling->acceleration == "anderson"
                               ? "anderson, depth " + std::to_string(scene.coupling->depth)
                               : std::string("none"))
      .set("L", P.L)
      .set("gamma", P.gamma)
      .set("dofs", dofs)
      .set("dt", scene.dt)
      .set("dt_growth", scene.growth)
      .set("steps", report.windows)
      .set("retries", report.retries)
      .set("fine_steps", report.windows * P.q)
      .set("coupling_iterations", report.coupling_iterations)
      .set("max_iterations_per_step", report.max_iterations_per_step)
      .set("max_contraction_ratio", report.max_contraction_ratio)
      .set("mean_contraction_ratio", report.mean_contraction_ratio)
      .set("bound_violations", report.bound_violations)
      .set("resolved_ratios", report.ratios)
      .set("unresolved_ratios", report.unresolved_ratios)
      .set("max_coupled_residual", report.max_coupled_residual)
      .set("converged", failure.empty())
      .set("status", !failure.empty() ? "failed" : signal ? "interrupted" : "completed")
      .set("last_completed_time", completed_time)
      .set("flow_solves", flow_stats.solves + second_pass_stats.solves) // both passes
      .set("mechanics_solves", mechanics_stats.solves)
      .set("monolithic_solves", coupled_stats.solves)
      .set("newton_iterations", mechanics_stats.newton_iterations + coupled_stats.newton_iterations)
      .set("linear_iterations", linear)
      .set("solvers", solvers)
      .set("timings", timings)
      .set("wall_time_s", wall)
      .set("left_out", left_out)
      .set("warnings", warnings)
      .set("mpi_ranks", [&] { int n; MPI_Comm_size(comm, &n); return n; }());
  if (contact_pressure)
    summary.set("contact", contact_json(contact));
  if (has_errors)
    summary.set("errors", errors);
  if (!failure.empty())
    summary.set("failure", failure);
  output.summary(summary);

  if (signal)
  {
    if (root)
      std::fprintf(stderr, "biotcontact: interrupted (signal %d) after step %d, t = %g: everything up to there is in %s\n",
                   signal, completed_steps, completed_time, directory.c_str());
    return 128 + signal;
  }
  if (!failure.empty())
  {
    if (root)
      std::fprintf(stderr, "biotcontact: error: %s (log: %s/iterations.csv)\n", failure.c_str(),
                   directory.c_str());
    return run_not_converged;
  }
  say("wrote " + output.xdmf_path() + " and " + directory + "/summary.json (" + std::to_string(wall) + " s)");
  return run_ok;
}

} // namespace biotcontact
