#include "simulation.h"

#include "diagnostics/closed_form.h"
#include "diagnostics/diagnostics.h"
#include "domain/domain.h"
#include "coupling/fixed_stress.h"
#include "coupling/single_solve.h"
#include "steps/flow_step.h"
#include "assembly/forms.h"
#include "steps/mechanics_step.h"
#include "steps/monolithic_step.h"
#include "output/directory_lock.h"
#include "output/checkpoint.h"
#include "output/interruption.h"
#include "output/output.h"
#include "output/progress.h"
#include "assembly/parameters.h"

#include <basix/finite-element.h>
#include <chrono>
#include <filesystem>
#include <cmath>
#include <sstream>
#include <cstdio>
#include <dolfinx/fem/utils.h>
#include <functional>
#include <optional>
#include <map>
#include <type_traits>
#include <xtensor/xarray.hpp>

namespace biotcontact
{
using namespace dolfinx;

namespace
{

std::int64_t global_size(const fem::FunctionSpace& V)
{
  return V.dofmap()->index_map->size_global() * V.dofmap()->index_map_bs();
}

/// Mean of one displacement component over the nodes of a boundary (collective).
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
  Json boundaries;
  for (const auto& [name, force, active] : c.boundaries)
    boundaries.set(name, Json().set("force", force).set("active_nodes", active));
  j.set("boundaries", boundaries);
  return j;
}

/// The relative L2 errors (and Terzaghi's settlement) at the final time
/// against the scene's closed form, Terzaghi or Mandel.
Json closed_form_errors(const Scene& scene, const Parameters& parameters, const Domain& domain, const CompiledForms& forms,
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
    terzaghi.emplace(Terzaghi{ref.height, parameters.G, parameters.lambda, parameters.alpha, parameters.storage, mobility, ref.load});
    p_exact = [&](double, double y) { return terzaghi->pressure(y - y0, t); };
    u_exact = [&](double, double y) { return std::array<double, 2>{0.0, terzaghi->displacement(y - y0, t)}; };
  }
  else
  {
    mandel.emplace(scene.mesh.upper[0], scene.mesh.upper[1], parameters.G, parameters.lambda, parameters.alpha, parameters.storage, mobility,
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

/// time.adaptive's part of summary.json: the tolerance, the steps rejected
/// or forced at dt_min, the contact breaks, the largest accepted estimate,
/// the steps taken.
Json adaptive_json(const AdaptiveSpec& spec, const CouplingReport& report, const TimeGrid& grid)
{
  const auto taken = std::span(grid.dt).first(std::min<std::size_t>(report.windows, grid.dt.size()));
  const auto [smallest, largest] = std::minmax_element(taken.begin(), taken.end());
  Json j;
  j.set("tolerance", spec.tolerance)
      .set("dt_min", spec.dt_min)
      .set("dt_max", spec.dt_max)
      .set("rejected_steps", report.rejected_steps)
      .set("forced_steps", report.forced_steps)
      .set("contact_breaks", report.contact_breaks)
      .set("max_error_estimate", report.max_error_estimate);
  if (!taken.empty())
    j.set("smallest_step", *smallest).set("largest_step", *largest);
  return j;
}

/// coupling.q = "auto"'s part of summary.json: its settings, the windows'
/// mean and largest q, the windows tried again with q = 1 (contact).
Json window_steps_json(const CouplingSpec& c, const CouplingReport& report)
{
  Json j;
  j.set("q_max", c.q_max)
      .set("q_tolerance", c.q_tolerance)
      .set("mean_q", report.windows ? static_cast<double>(report.fine_steps) / report.windows : 0.0)
      .set("largest_q", report.max_window_q)
      .set("q_rejections", report.q_rejections);
  return j;
}

/// The regions of the summary: each one's cells and its material's gamma
/// and L, and the cells in no region (the top-level material).
Json regions_json(const CellRegions& cells, const Materials& materials)
{
  Json regions;
  for (std::size_t r = 0; r < cells.names.size(); ++r)
    regions.set(cells.names[r], Json()
                                    .set("cells", static_cast<long>(cells.counts[r]))
                                    .set("gamma", materials.regions[r].gamma)
                                    .set("L", materials.regions[r].L));
  return regions.set("no region", Json()
                                    .set("cells", static_cast<long>(cells.outside))
                                    .set("gamma", materials.top.gamma)
                                    .set("L", materials.top.L));
}

/// mechanics.initial_equilibrium: replaces u = 0 by the displacement in
/// equilibrium with the loads at t = 0 and the initial pressure (a geostatic
/// initialisation). Otherwise loads present from the start, such as the
/// in-situ stresses, are applied in the first step as a sudden load, whose
/// undrained pressure response the first flow steps then carry.
void equilibrate(const Scene& scene, const Domain& domain, const CompiledForms& forms,
                 const Constants& constants, const Materials& materials, MechanicsStep* mechanics,
                 MonolithicStep* monolithic)
{
  if (mechanics)
  {
    mechanics->solve(0.0);
    return;
  }
  // The coupled system has no mechanics system of its own: one mechanics
  // step on its displacement space, loaded by its pressure, solved once.
  MechanicsStep step(scene, domain, forms, constants, materials, monolithic->V, monolithic->pressure);
  step.solve(0.0);
  monolithic->set_displacement(step.u->x()->array(), 0.0);
}

/// The steps a scene has (each scene allocates only the physics it has), and
/// the fields output and diagnostics read, whichever step produced them.
struct Steps
{
  std::unique_ptr<FlowStep> flow, second_pass; // second_pass: "multirate-two-pass"
  std::unique_ptr<MechanicsStep> mechanics;
  std::unique_ptr<MonolithicStep> monolithic;
  std::shared_ptr<const fem::FunctionSpace> V;
  std::shared_ptr<fem::Function<double>> u, p, contact_pressure, contact_active, contact_boundary;
  std::function<void(fem::Function<double>&)> compute_flux;
  std::function<ContactState()> compute_contact = [] { return ContactState{}; };

  std::unique_ptr<StepControl> step_control; // time.adaptive

  /// The memory of the time scheme and of time.adaptive by checkpoint name:
  /// BDF2's state one step before the last completed one
  /// (steps/time_scheme.h), the displacement one window before with
  /// coupling.q = "auto" (its last change), the step control's accepted states.
  std::vector<std::pair<std::string, fem::Function<double>*>> history(const Scene& scene) const
  {
    std::vector<std::pair<std::string, fem::Function<double>*>> h;
    if (scene.time_scheme == "bdf2" and flow)
      h.push_back({"pressure_before", flow->p_before.get()});
    const bool bdf2 = scene.time_scheme == "bdf2", q_auto = scene.coupling and scene.coupling->q_auto;
    if ((bdf2 or q_auto) and flow and flow->u_before) // q = "auto": the last window's change of u
      h.push_back({"displacement_before", flow->u_before.get()});
    if (bdf2 and flow and flow->u_before)
      h.push_back({"displacement_path_before", flow->u_path_before.get()});
    if (scene.time_scheme == "bdf2" and monolithic)
    {
      h.push_back({"pressure_before", monolithic->p_before.get()});
      h.push_back({"displacement_before", monolithic->u_before.get()});
    }
    if (step_control)
      for (const auto& entry : step_control->history())
        h.push_back(entry);
    return h;
  }

  /// The systems by their summary name, in the order of checkpoints.
  std::array<std::pair<const char*, System*>, 4> systems() const
  {
    return {{{"flow", flow ? &flow->system() : nullptr},
             {"mechanics", mechanics ? &mechanics->system() : nullptr},
             {"monolithic", monolithic ? &monolithic->system() : nullptr},
             {"flow_second_pass", second_pass ? &second_pass->system() : nullptr}}};
  }

  /// Assembly time of the steps' loads and matrices.
  double assembly_time() const
  {
    double t = 0;
    for (const FlowStep* f : {flow.get(), second_pass.get()})
      t += f ? f->assembly_time : 0.0;
    t += mechanics ? mechanics->assembly_time : 0.0;
    return t + (monolithic ? monolithic->assembly_time : 0.0);
  }
};

/// The contact fields of a step that has them.
template <class Step>
void take_contact_fields(Steps& s, Step* step)
{
  if (!step->has_contact())
    return;
  s.contact_pressure = step->contact_pressure;
  s.contact_active = step->contact_active;
  s.contact_boundary = step->contact_boundary;
  s.compute_contact = [step] { return step->contact_state(); };
}

/// The monolithic step: u, z and p in one system.
Steps monolithic_steps(const Scene& scene, const Domain& domain, const CompiledForms& forms,
                       const Constants& constants, const Materials& materials)
{
  Steps s;
  s.monolithic = std::make_unique<MonolithicStep>(scene, domain, forms, constants, materials);
  MonolithicStep* m = s.monolithic.get();
  s.V = m->V;
  s.u = m->u;
  s.p = m->pressure;
  s.compute_flux = [m](fem::Function<double>& out) { m->flux(out); };
  take_contact_fields(s, m);
  return s;
}

/// The flow step and the mechanics step of the split, or the one a single
/// physics has; "multirate-two-pass" adds the flow step without L.
Steps split_steps(const Scene& scene, const Domain& domain, const CompiledForms& forms, const Constants& constants,
                  const Materials& materials)
{
  Steps s;
  if (scene.mechanics)
    s.V = std::make_shared<fem::FunctionSpace>(fem::create_functionspace(forms.displacement_space, "v_0", domain.mesh));
  if (scene.flow)
  {
    s.flow = std::make_unique<FlowStep>(scene, domain, forms, constants, materials, scene.coupling ? s.V : nullptr);
    s.p = s.flow->pressure;
    if (scene.coupling and scene.coupling->scheme == "multirate-two-pass")
      s.second_pass
          = std::make_unique<FlowStep>(scene, domain, forms, constants, materials.without_stabilisation(), s.V);
    FlowStep* f = s.flow.get();
    s.compute_flux = [f](fem::Function<double>& out) { f->flux(out); };
  }
  if (scene.mechanics)
  {
    s.mechanics = std::make_unique<MechanicsStep>(scene, domain, forms, constants, materials, s.V, s.p);
    s.u = s.mechanics->u;
    take_contact_fields(s, s.mechanics.get());
  }
  return s;
}

/// The fields written at each output time: the unknowns and what is derived
/// from them (cell-averaged flux, volumetric stress sigma_v, contact).
class OutputFields
{
public:
  OutputFields(const Domain& domain, const CompiledForms& forms, const Constants& constants,
               const Materials& materials, Steps& steps, Output& output)
      : _forms(forms), _constants(constants), _materials(materials), _steps(steps), _output(output)
  {
    const auto cell = mesh::cell_type_to_basix_type(domain.mesh->topology().cell_type());
    const basix::FiniteElement dg0 = basix::create_element(
        basix::element::family::P, cell, 0, basix::element::lagrange_variant::unset, true);
    if (steps.p)
    {
      steps.p->name = "pressure";
      _flux = std::make_shared<fem::Function<double>>(
          std::make_shared<fem::FunctionSpace>(fem::create_functionspace(domain.mesh, dg0, domain.dim())));
      _flux->name = "flux";
    }
    if (steps.u)
    {
      steps.u->name = "displacement";
      auto Q0 = std::make_shared<fem::FunctionSpace>(fem::create_functionspace(domain.mesh, dg0, 1));
      _sigma_v = std::make_shared<fem::Function<double>>(Q0);
      _sigma_v->name = "sigma_v";
      if (!steps.p)
        _zero_pressure = std::make_shared<fem::Function<double>>(Q0);
      if (steps.contact_pressure)
      {
        steps.contact_pressure->name = "contact_pressure";
        steps.contact_active->name = "contact_active";
      }
    }
  }

  void write_flow(double t)
  {
    _output.write(*_steps.p, t);
    _steps.compute_flux(*_flux);
    _output.write(*_flux, t);
  }

  /// Also updates `contact` (and the contact fields).
  void write_mechanics(double t)
  {
    contact = _steps.compute_contact();
    volumetric_stress(_forms, _constants, _materials, _steps.u, _steps.p ? _steps.p : _zero_pressure, *_sigma_v);
    _output.write(*_steps.u, t);
    _output.write(*_sigma_v, t);
    if (_steps.contact_pressure)
    {
      _output.write(*_steps.contact_pressure, t);
      _output.write(*_steps.contact_active, t);
    }
  }

  ContactState contact; // at the last mechanics output

private:
  const CompiledForms& _forms;
  const Constants& _constants;
  const Materials& _materials;
  Steps& _steps;
  Output& _output;
  std::shared_ptr<fem::Function<double>> _flux, _sigma_v, _zero_pressure;
};

/// The state a restart needs after `steps` completed steps (checkpoint.h).
Checkpoint capture_checkpoint(int steps, double time, const Steps& s, const mesh::Mesh& mesh, CouplingReport report,
                              const std::string& output, const TimeGrid& grid, const Scene& scene)
{
  Checkpoint c;
  c.steps = steps;
  c.time = time;
  c.arrays["times"] = grid.t; // the grid as retries left it (the same on every rank)
  c.arrays["time_steps"] = grid.dt;
  c.arrays["mesh"] = mesh_signature(mesh);
  auto keep = [&](const std::vector<UnknownsPart>& parts, std::span<const double> unknowns)
  {
    for (const UnknownsPart& part : parts)
      c.fields[part.name] = keyed_values(mesh, part, unknowns);
  };
  if (s.flow)
    keep(s.flow->parts(), s.flow->unknowns());
  if (s.mechanics)
    keep({{"displacement", s.V, {}}}, s.mechanics->u->x()->array());
  if (s.monolithic)
    keep(s.monolithic->parts(), s.monolithic->unknowns());
  for (const auto& [name, f] : s.history(scene))
    keep({{name, f->function_space(), {}}}, f->x()->array());
  for_each_checkpointed(report, [&](const char* name, auto& value) { c.numbers[name] = value; });
  const auto systems = s.systems();
  for (std::size_t i = 0; i < systems.size(); ++i)
    if (const System* system = systems[i].second)
    {
      const SolverStatistics st = system->statistics();
      for (const auto& [name, count] : solver_counts)
        c.numbers[std::to_string(i) + "." + name] = st.*count;
    }
  c.output = output;
  return c;
}

/// Loads the stored unknowns into the steps, whatever the partition;
/// refuses a checkpoint of another mesh, or one that lacks any of them
/// (collective).
void restore_unknowns(const Checkpoint& c, Steps& s, const mesh::Mesh& mesh, MPI_Comm comm,
                      const std::string& directory, const Scene& scene)
{
  const auto stored_mesh = c.arrays.find("mesh");
  const std::string difference
      = mesh_difference(stored_mesh == c.arrays.end() ? std::vector<double>{} : stored_mesh->second,
                        mesh_signature(mesh));
  if (not difference.empty())
    throw SceneError("--restart " + directory + ": the checkpoint does not match this mesh (" + difference + ")");
  auto restore = [&](const std::vector<UnknownsPart>& parts, std::span<double> unknowns)
  {
    for (const UnknownsPart& part : parts)
    {
      const auto stored = c.fields.find(part.name);
      std::int64_t missing = stored == c.fields.end() ? 1 : restore_values(mesh, part, stored->second, unknowns);
      MPI_Allreduce(MPI_IN_PLACE, &missing, 1, MPI_INT64_T, MPI_SUM, comm);
      if (missing > 0)
        throw SceneError("--restart " + directory + ": the checkpoint does not match this mesh ("
                         + std::to_string(missing) + " values of the " + part.name + " not in it)");
    }
  };
  if (s.flow)
  {
    std::vector<double> w(s.flow->unknowns().begin(), s.flow->unknowns().end());
    restore(s.flow->parts(), w);
    s.flow->set_unknowns(w);
  }
  if (s.mechanics)
    restore({{"displacement", s.V, {}}}, s.mechanics->u->x()->mutable_array());
  if (s.monolithic)
  {
    std::vector<double> x(s.monolithic->unknowns().begin(), s.monolithic->unknowns().end());
    restore(s.monolithic->parts(), x);
    s.monolithic->set_unknowns(x);
  }
  for (const auto& [name, f] : s.history(scene))
    restore({{name, f->function_space(), {}}}, f->x()->mutable_array());
}

/// Loads a checkpoint into the steps, the report, the grid and the solver counts.
void restore_checkpoint(const Checkpoint& c, Steps& s, const mesh::Mesh& mesh, MPI_Comm comm,
                        const std::string& directory, CouplingReport& report, TimeGrid& grid, const Scene& scene)
{
  grid.t = c.arrays.at("times");
  grid.dt = c.arrays.at("time_steps");
  restore_unknowns(c, s, mesh, comm, directory, scene);
  for_each_checkpointed(report, [&](const char* name, auto& value)
                        { value = static_cast<std::remove_reference_t<decltype(value)>>(c.numbers.at(name)); });
  const auto systems = s.systems();
  for (std::size_t i = 0; i < systems.size(); ++i)
    if (System* system = systems[i].second)
    {
      SolverStatistics earlier;
      for (const auto& [name, count] : solver_counts)
        earlier.*count = static_cast<long>(c.numbers.at(std::to_string(i) + "." + name));
      system->add_earlier(earlier);
    }
}

/// Per system: what solved it, how often it was set up (factorised) and
/// solved, and where its time went; the solvers' and timings' tables.
std::pair<Json, Json> solver_summaries(const Steps& steps, bool inexact_coupling)
{
  Json solvers, timings;
  for (const auto& [name, system] : steps.systems())
  {
    if (!system)
      continue;
    const SolverStatistics st = system->statistics();
    const bool direct = system->method() == Method::direct;
    Json j;
    j.set("solver", method_name(system->method()))
        .set("chosen_by", system->method_reason())
        .set("method", system->description())
        .set("unknowns", system->unknowns())
        .set("solves", st.solves)
        .set("factorizations", direct ? st.setups : 0)
        .set("preconditioner_setups", st.setups)
        .set("inexact_coupling", !direct and !steps.monolithic and inexact_coupling)
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
  return {solvers, timings};
}

/// The statistics of each system (zero for a system the scene has not).
std::map<std::string, SolverStatistics> statistics(const Steps& steps)
{
  std::map<std::string, SolverStatistics> result;
  for (const auto& [name, system] : steps.systems())
    result[name] = system ? system->statistics() : SolverStatistics{};
  return result;
}

/// The unknowns of each physics (global counts).
Json dofs_json(const Steps& steps, const Domain& domain)
{
  Json dofs;
  if (steps.u)
    dofs.set("displacement", static_cast<long>(global_size(*steps.V)));
  if (steps.p)
    dofs.set("pressure", static_cast<long>(global_size(*steps.p->function_space())))
        .set("flux", static_cast<long>(domain.mesh->topology().index_map(domain.dim() - 1)->size_global())); // RT0
  return dofs;
}

/// @brief One run of a scene, in the order of its story: make the domain,
/// set up the steps, open the output, start or restore, the time loop, the
/// summary and the exit status.
class Simulation
{
public:
  Simulation(const Scene& scene, const std::string& directory, MPI_Comm comm, const RunControl& control)
      : _scene(scene), _directory(directory), _comm(comm), _control(control), _progress(comm, scene.progress_interval)
  {
  }

  int run()
  {
    make_domain();
    describe();
    _steps = _scene.coupling and _scene.coupling->scheme == "monolithic"
                 ? monolithic_steps(_scene, *_domain, *_forms, _constants, _materials)
                 : split_steps(_scene, *_domain, *_forms, _constants, _materials);
    if (_scene.adaptive)
      _steps.step_control = std::make_unique<StepControl>(_scene, _steps.p ? _steps.p->function_space() : nullptr,
                                                          _steps.V);
    try
    {
      open_output();
      start_or_restore();
      time_loop();
    }
    catch (const OutputError& e)
    {
      output_failed(e);
    }
    write_summary();
    return exit_status();
  }

private:
  void make_domain();
  void describe();
  void open_output();
  void start_or_restore();
  WindowObserver observer();
  void report_newton_steps();
  void time_loop();
  std::string step_being_computed() const;
  int planned_steps() const;
  void output_failed(const OutputError& e);
  bool stop();
  void write_summary();
  int exit_status() const;

  const Scene& _scene;
  const std::string _directory;
  MPI_Comm _comm;
  const RunControl& _control;
  Progress _progress;
  std::optional<Domain> _domain;
  const CompiledForms* _forms = nullptr;
  Parameters _parameters; // of the top-level material; gamma the largest of any cell
  Materials _materials;
  Constants _constants;
  std::string _left_out, _warnings;
  Steps _steps;
  std::optional<Checkpoint> _resumed;
  std::optional<DirectoryLock> _lock;
  std::unique_ptr<Output> _output;
  std::unique_ptr<OutputFields> _fields;
  TimeGrid _grid;
  CouplingReport _report;
  int _completed_steps = 0; // mechanics steps (windows) written
  double _completed_time = 0;
  int _saved = 0;           // the step of the last checkpoint
  bool _checkpointing = false; // writing the checkpoint of the last completed step
  int _signal = 0;          // the interruption that ended the run
  std::string _failure;     // why the run failed
  bool _output_failed = false; // ... because a file could not be written
};

/// The mesh and its tags, the compiled forms of its cell type, the derived
/// parameters, the materials of its cells and the constants of the forms.
void Simulation::make_domain()
{
  _domain.emplace(create_domain(_scene, _comm));
  check_expressions(_scene, *_domain, _comm);
  _forms = &compiled_forms(_domain->mesh->topology().cell_type());
  _materials = make_materials(_scene, *_domain, *_forms);
  _parameters = derive_parameters(_scene);
  _parameters.gamma = _materials.gamma;
  _constants = make_constants(_scene, _parameters);
}

/// Says what the scene leaves out, and warns where the method is known to
/// degrade instead of returning poor numbers silently (docs/stability.md).
void Simulation::describe()
{
  auto leave_out = [&](const std::string& what) { _left_out += (_left_out.empty() ? "" : "; ") + what; };
  if (!_scene.flow)
    leave_out("flow (no [flow] table): no flux or pressure unknowns");
  if (!_scene.mechanics)
    leave_out("mechanics (no [mechanics] table): no displacement unknowns");
  if (_scene.mechanics and !_scene.has_contact())
    leave_out("contact solver (no contact boundary): linear mechanics solve");
  if (_scene.flow and !_scene.flow->gravity)
    leave_out("gravity");
  if (_scene.mechanics and !_scene.mechanics->body_force and !_scene.cellwise_body_force())
    leave_out("body force");
  const int d = _domain->dim();
  _progress.say("biotcontact: scene " + _scene.name + " (" + _scene.file + "), " + std::to_string(d) + "D, "
                + std::to_string(_domain->mesh->topology().index_map(d)->size_global()) + " cells");
  _progress.say("left out: " + (_left_out.empty() ? std::string("nothing") : _left_out));

  auto warn = [&](const std::string& what)
  {
    _warnings += (_warnings.empty() ? "" : "; ") + what;
    _progress.say("warning: " + what);
  };
  const CellRegions& regions = _domain->regions;
  for (std::size_t r = 0; r < regions.names.size(); ++r)
    _progress.say("region " + regions.names[r] + ": " + std::to_string(regions.counts[r]) + " cells"
                  + (_scene.coupling ? ", gamma = " + std::to_string(_materials.regions[r].gamma) : ""));
  for (std::size_t r = 0; _scene.mechanics and r <= regions.names.size(); ++r)
  {
    const Parameters& m = r < regions.names.size() ? _materials.regions[r] : _materials.top;
    const double nu = m.lambda / (2 * (m.lambda + m.G));
    if (nu > 0.49 and (r < regions.names.size() or regions.outside > 0))
      warn((r < regions.names.size() ? "region " + regions.names[r] + ": " : std::string()) + "nu = "
           + std::to_string(nu) + " > 0.49: P1 displacements lock as nu -> 0.5 "
           "(too stiff a response, worse on coarse meshes)");
  }
  if (const std::string w = gamma_warning(_scene, _materials.gamma_peak()); !w.empty())
    warn(w);
}

/// The time grid, the checkpoint a restart goes on from (loaded into the
/// steps), the output files (created, or those of the checkpoint's run) and
/// the fields written into them.
void Simulation::open_output()
{
  // The lock first: nothing in the directory is read, created or truncated
  // while another run holds it. A restart of a directory that does not
  // exist is refused by read_checkpoint, without creating it.
  if (!_control.restart or std::filesystem::is_directory(_directory))
    _lock.emplace(_comm, _directory);
  _grid = time_grid(_scene); // a retry (time.retry) halves some of its steps
  if (_control.restart)
  {
    // Loaded before the files are opened: a checkpoint that does not match
    // is refused with the files as they were.
    _resumed = read_checkpoint(_comm, _directory, _control.fingerprint);
    restore_checkpoint(*_resumed, _steps, *_domain->mesh, _comm, _directory, _report, _grid, _scene);
  }
  _output = std::make_unique<Output>(_comm, _directory, _domain->mesh, _scene.write_xdmf,
                                     _resumed ? &_resumed->output : nullptr);
  _fields = std::make_unique<OutputFields>(*_domain, *_forms, _constants, _materials, _steps, *_output);
}

/// The initial state, written at t = 0, or the checkpoint's step and time.
void Simulation::start_or_restore()
{
  if (_resumed)
  {
    _saved = _completed_steps = _resumed->steps;
    _completed_time = _resumed->time;
    if (_steps.u)
      _fields->contact = _steps.compute_contact();
    _progress.say("restarted from the checkpoint at step " + std::to_string(_completed_steps) + ", t = "
                  + std::to_string(_completed_time));
    return;
  }
  if (_scene.mechanics and _scene.mechanics->initial_equilibrium)
    equilibrate(_scene, *_domain, *_forms, _constants, _materials, _steps.mechanics.get(), _steps.monolithic.get());
  if (_steps.p)
    _fields->write_flow(0.0);
  if (_steps.u)
    _fields->write_mechanics(0.0);
  if (_steps.contact_boundary)
    _output->write(*_steps.contact_boundary, 0.0); // once: every later time repeats it
  if (_steps.step_control)
    _steps.step_control->start(_steps.p ? _steps.p->x()->array() : std::span<const double>(),
                               _steps.u ? _steps.u->x()->array() : std::span<const double>(), _report);
}

/// After each completed (and written) step: a checkpoint every
/// checkpoint_every steps and at an interruption; then whether to stop.
bool Simulation::stop()
{
  auto save = [&]
  {
    _checkpointing = true;
    write_checkpoint(_comm, _directory, _control.fingerprint,
                     capture_checkpoint(_completed_steps, _completed_time, _steps, *_domain->mesh, _report,
                                        _output->position(), _grid, _scene));
    _checkpointing = false;
    _saved = _completed_steps;
  };
  if (_scene.checkpoint_every > 0 and _completed_steps % _scene.checkpoint_every == 0)
    save();
  _signal = interruption_signal(_comm);
  if (_signal and _scene.checkpoint_every > 0 and _saved != _completed_steps)
    save();
  return _signal != 0;
}

/// What the coupling schemes tell the run: write each step, print the
/// progress, checkpoint, stop at an interruption.
WindowObserver Simulation::observer()
{
  WindowObserver o;
  o.flow_state = [this](double t)
  {
    if (_scene.is_output_time(t))
      _fields->write_flow(t);
  };
  o.mechanics_state = [this](double t, int step, int iterations)
  {
    if (_steps.u and _scene.is_output_time(t))
      _fields->write_mechanics(t);
    else if (_steps.u)
      _fields->contact = _steps.compute_contact();
    _completed_steps = step;
    _completed_time = t;
    _progress.step(step, planned_steps(), t, iterations, _fields->contact.active_nodes);
  };
  o.stop = [this] { return stop(); };
  o.retry = [this](const std::string& message) { _progress.say(message); };
  o.iteration = [this](int step, int iteration, double dp, double du)
  {
    char what[160];
    std::snprintf(what, sizeof what, "step %d: coupling iteration %d, increments dp %.3g du %.3g", step,
                  iteration, dp, du);
    _progress.heartbeat(what);
  };
  return o;
}

/// A contact solve longer than 10 s (a large monolithic step) prints its
/// Newton steps as it goes, like the coupling iterations of the split.
void Simulation::report_newton_steps()
{
  for (const auto& [name, system] : _steps.systems())
    if (system and system->has_contact())
      system->contact().on_newton_step = [this, name = std::string(name)](int iteration)
      {
        _progress.heartbeat("step " + std::to_string(_completed_steps + 1) + ": " + name + " contact Newton step "
                            + std::to_string(iteration));
      };
}

/// The steps from t = 0 (or the checkpoint) to the end: the fixed-stress
/// split, or one solve per step. A failure ends the loop with what was
/// finished written; it names the step it was computing.
void Simulation::time_loop()
{
  const WindowObserver o = observer();
  report_newton_steps();
  _progress.start_loop(_completed_steps, planned_steps());
  try
  {
    if (_scene.coupling and !_steps.monolithic)
    {
      ContractionNorm contraction(*_forms, _materials, _parameters.q, _steps.V, _steps.flow->pressure_space());
      run_fixed_stress(_scene, _parameters, _constants, _materials, *_steps.flow, _steps.second_pass.get(),
                       *_steps.mechanics, contraction, *_output, o, _report, _grid, _steps.step_control.get());
    }
    else
      run_single_solve(_scene, _constants, _steps.flow.get(), _steps.mechanics.get(), _steps.monolithic.get(), o,
                       _report, _grid, _steps.step_control.get());
  }
  catch (const CouplingError& e)
  {
    _failure = e.what(); // names its step and the last increments
  }
  catch (const SolverError& e)
  {
    _failure = step_being_computed() + ": " + e.what();
    _report.windows = _completed_steps;
  }
  _fields->contact = _steps.compute_contact();
}

/// The mechanics steps (windows) of the run, for the progress: with
/// coupling.q = "auto" those done and the rest at the last window's q.
int Simulation::planned_steps() const
{
  const int q = _report.window_q > 0 ? _report.window_q : _parameters.q;
  return _report.windows + static_cast<int>((_grid.steps() - _report.fine_steps + q - 1) / q);
}

/// "step N (t = T)" of the step after the last completed one.
std::string Simulation::step_being_computed() const
{
  const int step = _completed_steps + 1;
  std::ostringstream s;
  s << "step " << step;
  if (!_grid.t.empty())
    s << " (t = " << _grid.t[std::min<std::size_t>(_report.fine_steps + _parameters.q, _grid.t.size() - 1)] << ")";
  return s.str();
}

/// A file could not be written: the run ends with what it wrote before,
/// and the failure names the step it was writing.
void Simulation::output_failed(const OutputError& e)
{
  _failure = (_checkpointing ? "after step " + std::to_string(_completed_steps) : step_being_computed())
             + ": " + e.what();
  _output_failed = true;
  _report.windows = _completed_steps;
}

/// summary.json: the scheme, sizes, counts, contraction measures, solvers,
/// timings, contact and closed-form errors of the run, whatever its end
/// (when the disk is full, as far as it can be written).
void Simulation::write_summary()
{
  if (!_output)
    return;
  const bool has_errors = _scene.reference and _failure.empty() and _signal == 0;
  auto st = statistics(_steps);
  auto [solvers, timings] = solver_summaries(_steps, _scene.solver.inexact_coupling);
  double assembly = _steps.assembly_time();
  for (const auto& [name, s] : st)
    assembly += s.assembly_time;
  timings.set("assembly", assembly).set("output", _output->time);
  Json linear;
  linear.set("flow", st["flow"].linear_iterations + st["flow_second_pass"].linear_iterations)
      .set("mechanics", st["mechanics"].linear_iterations)
      .set("monolithic", st["monolithic"].linear_iterations);
  const CouplingSpec* c = _scene.coupling ? &*_scene.coupling : nullptr;
  Json summary;
  summary.set("scene", _scene.name).set("scheme", c ? c->scheme : (_steps.flow ? "flow-only" : "mechanics-only"));
  if (c and c->q_auto)
    summary.set("q", "auto");
  else
    summary.set("q", _parameters.q);
  summary.set("L_choice", c ? c->L_choice : "none")
      .set("acceleration", c and c->acceleration == "anderson" ? "anderson, depth " + std::to_string(c->depth)
                                                               : std::string("none"))
      .set("L", _parameters.L)
      .set("gamma", _parameters.gamma)
      .set("dofs", dofs_json(_steps, *_domain))
      .set("dt", _scene.dt)
      .set("dt_growth", _scene.growth)
      .set("time_scheme", _scene.time_scheme)
      .set("steps", _report.windows)
      .set("retries", _report.retries)
      .set("fine_steps", _report.fine_steps)
      .set("coupling_iterations", _report.coupling_iterations)
      .set("max_iterations_per_step", _report.max_iterations_per_step)
      .set("max_contraction_ratio", _report.max_contraction_ratio)
      .set("mean_contraction_ratio", _report.mean_contraction_ratio)
      .set("bound_violations", _report.bound_violations)
      .set("resolved_ratios", _report.ratios)
      .set("unresolved_ratios", _report.unresolved_ratios)
      .set("max_coupled_residual", _report.max_coupled_residual)
      .set("converged", _failure.empty())
      .set("status", !_failure.empty() ? "failed" : _signal ? "interrupted" : "completed")
      .set("last_completed_time", _completed_time)
      .set("flow_solves", st["flow"].solves + st["flow_second_pass"].solves) // both passes
      .set("mechanics_solves", st["mechanics"].solves)
      .set("monolithic_solves", st["monolithic"].solves)
      .set("newton_iterations", st["mechanics"].newton_iterations + st["monolithic"].newton_iterations)
      .set("linear_iterations", linear)
      .set("solvers", solvers)
      .set("timings", timings)
      .set("wall_time_s", _progress.elapsed())
      .set("left_out", _left_out)
      .set("warnings", _warnings)
      .set("mpi_ranks", [&] { int n; MPI_Comm_size(_comm, &n); return n; }());
  if (c and c->q_auto)
    summary.set("window_steps", window_steps_json(*c, _report));
  if (_scene.adaptive)
    summary.set("adaptive", adaptive_json(*_scene.adaptive, _report, _grid));
  if (!_domain->regions.names.empty())
    summary.set("regions", regions_json(_domain->regions, _materials));
  if (_steps.contact_pressure)
    summary.set("contact", contact_json(_fields->contact));
  if (has_errors)
    summary.set("errors", closed_form_errors(_scene, _parameters, *_domain, *_forms, _steps.u, _steps.p));
  if (!_failure.empty())
    summary.set("failure", _failure);
  try
  {
    _output->summary(summary);
  }
  catch (const OutputError& e)
  {
    if (_output_failed)
      _failure += "; summary.json could not be written either";
    else
      output_failed(e);
  }
}

/// run_ok; 128 + the signal of an interruption; run_not_converged after a
/// failure (everything finished is written).
int Simulation::exit_status() const
{
  const bool root = is_rank0(_comm);
  if (_signal)
  {
    if (root)
      std::fprintf(stderr, "biotcontact: interrupted (signal %d) after step %d, t = %g: everything up to there is in %s\n",
                   _signal, _completed_steps, _completed_time, _directory.c_str());
    return 128 + _signal;
  }
  if (_output_failed)
  {
    if (root)
      std::fprintf(stderr, "biotcontact: error: %s (steps 1 to %d, t <= %g, are in %s%s)\n", _failure.c_str(),
                   _completed_steps, _completed_time, _directory.c_str(),
                   _saved > 0 ? ("; its last checkpoint is of step " + std::to_string(_saved)).c_str() : "");
    return run_output_failed;
  }
  if (!_failure.empty())
  {
    if (root)
      std::fprintf(stderr, "biotcontact: error: %s (log: %s/iterations.csv)\n", _failure.c_str(), _directory.c_str());
    return run_not_converged;
  }
  if (root)
    std::printf("wrote %s and %s/summary.json (%f s)\n", _output->xdmf_path().c_str(), _directory.c_str(),
                _progress.elapsed()), std::fflush(stdout);
  return run_ok;
}

} // namespace

int run(const Scene& scene, const std::string& directory, MPI_Comm comm, const RunControl& control)
{
  return Simulation(scene, directory, comm, control).run();
}

} // namespace biotcontact
