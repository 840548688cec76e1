#include "output/summary.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <map>

namespace biotcontact
{
using namespace dolfinx;

namespace
{

std::int64_t global_size(const fem::FunctionSpace& V)
{
  return V.dofmap()->index_map->size_global() * V.dofmap()->index_map_bs();
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
  if (!c.faults.empty())
  {
    // Per fault: its largest opening and slip (m), and the length (2D) or
    // area (3D) of it in contact, and of its pairs in the states slip and
    // stick (contact_law.h).
    Json faults;
    for (const FaultSummary& f : c.faults)
      faults.set(f.name, Json()
                             .set("max_opening", f.max_opening)
                             .set("max_slip", f.max_slip)
                             .set("closed", f.closed)
                             .set("slipping", f.slipping)
                             .set("stuck", f.stuck));
    j.set("faults", faults);
  }
  return j;
}

Json errors_json(const ReferenceErrors& e)
{
  Json errors;
  errors.set("time", e.time)
      .set("pressure_rel_l2", e.pressure_rel_l2)
      .set("displacement_rel_l2", e.displacement_rel_l2);
  if (e.settlement)
    errors.set("settlement", e.settlement->computed)
        .set("settlement_exact", e.settlement->exact)
        .set("settlement_rel", e.settlement->relative);
  return errors;
}

/// time.adaptive's part: the tolerance, the steps rejected or forced at
/// dt_min, the contact breaks, the largest accepted estimate, the steps taken.
Json adaptive_json(const AdaptiveSpec& spec, const CouplingReport& report, const TimeGrid& grid)
{
  const auto taken = std::span(grid.dt).first(std::min<std::size_t>(report.windows, grid.dt.size()));
  const auto [smallest, largest] = std::minmax_element(taken.begin(), taken.end());
  Json j;
  j.set("tolerance", spec.tolerance)
      .set("dt_min", spec.dt_min)
      .set("dt_max", spec.dt_max)
      .set("rejected_steps", report.adaptive.rejected_steps)
      .set("forced_steps", report.adaptive.forced_steps)
      .set("contact_breaks", report.adaptive.contact_breaks)
      .set("max_error_estimate", report.adaptive.max_error_estimate);
  if (!taken.empty())
    j.set("smallest_step", *smallest).set("largest_step", *largest);
  return j;
}

/// coupling.acceleration as summary.json gives it: "none", "anderson, depth
/// m" or "auto, depth m" (Anderson's where the plain iteration stagnates).
std::string acceleration_text(const CouplingSpec* c)
{
  if (!c or c->acceleration == Acceleration::none or c->scheme == CouplingScheme::monolithic)
    return "none";
  return std::string(c->acceleration == Acceleration::anderson ? "anderson" : "auto") + ", depth "
         + std::to_string(c->depth);
}

/// coupling.q = "auto"'s part: its settings, the windows' mean and largest
/// q, the windows tried again with q = 1 (contact).
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

/// Each region's cells and its material's gamma and L, and the cells in no
/// region (the top-level material).
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

/// The steps whose systems solved the run: the scheme's, and those of
/// the monolithic scheme that solved the steps the split failed at
/// (coupling.fallback).
std::vector<const Step*> solving_steps(const SummaryInput& in)
{
  std::vector<const Step*> steps(in.scheme.steps().begin(), in.scheme.steps().end());
  if (in.fallback)
    steps.insert(steps.end(), in.fallback->steps().begin(), in.fallback->steps().end());
  return steps;
}

/// Per system: what solved it, how often it was set up (factorised) and
/// solved, and where its time went; the solvers' and timings' tables.
std::pair<Json, Json> solver_summaries(const std::vector<const Step*>& steps, bool inexact_coupling)
{
  Json solvers, timings;
  for (const Step* step : steps)
  {
    const System& system = step->system();
    const SolverStatistics st = system.statistics();
    const bool direct = system.method() == Method::direct;
    Json j;
    j.set("solver", method_name(system.method()))
        .set("chosen_by", system.method_reason())
        .set("method", system.description())
        .set("unknowns", system.unknowns())
        .set("solves", st.solves)
        .set("factorizations", direct ? st.setups : 0)
        .set("preconditioner_setups", st.setups)
        .set("inexact_coupling", !direct and inexact_coupling)
        .set("back_solves", st.back_solves)
        .set("linear_iterations", st.linear_iterations);
    if (system.has_contact())
      j.set("newton_iterations", st.newton_iterations)
          .set("active_set_changes", st.active_set_changes)
          .set("schur_columns", st.schur_columns)
          .set("schur_factorizations", st.schur_factorizations)
          .set("contact_factorizations", st.contact_factorizations);
    solvers.set(step->name(), j);
    timings.set(step->name(), Json()
                                  .set("total", st.total_time)
                                  .set("setup", st.setup_time)
                                  .set("solve", st.solve_time)
                                  .set("schur_complement", st.schur_time)
                                  .set("other", st.total_time - st.setup_time - st.solve_time - st.schur_time)
                                  .set("matrix_assembly", st.assembly_time));
  }
  return {solvers, timings};
}

/// The statistics of each system (zero for a system the scene has not).
std::map<std::string, SolverStatistics> statistics(const std::vector<const Step*>& steps)
{
  std::map<std::string, SolverStatistics> result;
  for (const char* name : {"flow", "mechanics", "monolithic", "flow_second_pass"})
    result[name] = {};
  for (const Step* step : steps)
    result[step->name()] = step->system().statistics();
  return result;
}

/// The unknowns of each physics (global counts).
Json dofs_json(const Scheme& scheme, const Domain& domain)
{
  Json dofs;
  if (scheme.u)
    dofs.set("displacement", static_cast<long>(global_size(*scheme.V)));
  if (scheme.p)
    dofs.set("pressure", static_cast<long>(global_size(*scheme.p->function_space())))
        .set("flux", static_cast<long>(domain.mesh->topology().index_map(domain.dim() - 1)->size_global())); // RT0
  return dofs;
}

/// The scheme's settings: its name, q, L and gamma, the acceleration.
Json scheme_json(const Problem& problem, const Scheme& scheme)
{
  const CouplingSpec* c = problem.scene.coupling ? &*problem.scene.coupling : nullptr;
  Json j;
  j.set("scene", problem.scene.name).set("scheme", c ? name_of(c->scheme) : (scheme.p ? "flow-only" : "mechanics-only"));
  if (c and c->q_auto)
    j.set("q", "auto");
  else
    j.set("q", problem.parameters.q);
  return j.set("L_choice", c ? name_of(c->L_choice) : "none")
      .set("acceleration", acceleration_text(c))
      .set("fallback", c ? name_of(c->fallback) : "none")
      .set("L", problem.parameters.L)
      .set("gamma", problem.parameters.gamma);
}

/// Per fault the seismic moment of each accepted step (FaultSummary::moment)
/// and their sum; in 3D the moment magnitude of the sum, Mw = (2/3)
/// (log10 M0 - 9.1) (M0 in N m; in 2D M0 is per metre and has none).
Json seismic_moment_json(const SeismicMoments& m, int dim)
{
  const std::size_t width = m.names.size() + 1;
  std::vector<double> times;
  for (std::size_t r = 0; r < m.steps.size(); r += width)
    times.push_back(m.steps[r]);
  Json faults;
  for (std::size_t f = 0; f < m.names.size(); ++f)
  {
    std::vector<double> moments;
    for (std::size_t r = 0; r < m.steps.size(); r += width)
      moments.push_back(m.steps[r + 1 + f]);
    const double total = std::accumulate(moments.begin(), moments.end(), 0.0);
    Json fault;
    fault.set("total", total);
    if (dim == 3 and total > 0)
      fault.set("magnitude", 2.0 / 3.0 * (std::log10(total) - 9.1));
    faults.set(m.names[f], fault.set("times", times).set("moments", moments));
  }
  return faults;
}

/// Per conduit fault, its fluid volumes since the start (FaultVolumes).
Json fault_volumes_json(const std::vector<std::pair<std::string, FaultVolumes>>& volumes)
{
  Json faults;
  for (const auto& [name, v] : volumes)
    faults.set(name, Json()
                         .set("injected", v.injected)
                         .set("stored", v.stored)
                         .set("exchanged", v.exchanged)
                         .set("outflow", v.outflow)
                         .set("intersections", v.intersections));
  return faults;
}

/// Per set of conduit faults that meet ("a & b"): its junctions and the
/// volume rate through them at the last step's end (IntersectionRate).
Json intersections_json(const std::vector<IntersectionRate>& intersections)
{
  Json meets;
  for (const IntersectionRate& r : intersections)
  {
    std::string key;
    for (const std::string& name : r.faults)
      key += (key.empty() ? "" : " & ") + name;
    meets.set(key, Json().set("junctions", static_cast<long>(r.junctions)).set("rate", r.rate));
  }
  return meets;
}

} // namespace

Json run_summary(const SummaryInput& in, const RunOutcome& outcome)
{
  const Scene& scene = in.problem.scene;
  const CouplingReport& r = in.report;
  const std::vector<const Step*> steps = solving_steps(in);
  auto st = statistics(steps);
  const bool monolithic = scene.coupling and scene.coupling->scheme == CouplingScheme::monolithic;
  auto [solvers, timings] = solver_summaries(steps, !monolithic and scene.solver.inexact_coupling);
  double assembly = in.scheme.assembly_time() + (in.fallback ? in.fallback->assembly_time() : 0.0);
  for (const auto& [name, s] : st)
    assembly += s.assembly_time;
  timings.set("assembly", assembly).set("output", outcome.output_time);
  Json linear;
  linear.set("flow", st["flow"].linear_iterations + st["flow_second_pass"].linear_iterations)
      .set("mechanics", st["mechanics"].linear_iterations)
      .set("monolithic", st["monolithic"].linear_iterations);
  Json summary = scheme_json(in.problem, in.scheme);
  summary.set("dofs", dofs_json(in.scheme, in.problem.domain))
      .set("dt", scene.dt)
      .set("dt_growth", scene.growth)
      .set("time_scheme", name_of(scene.time_scheme))
      .set("steps", r.windows)
      .set("retries", r.retries)
      .set("accelerated_windows", r.accelerated_windows)
      .set("pinned_windows", r.pinned_windows)
      .set("fallback_steps", r.fallback_steps)
      .set("fine_steps", r.fine_steps)
      .set("coupling_iterations", r.coupling_iterations)
      .set("max_iterations_per_step", r.max_iterations_per_step)
      .set("max_contraction_ratio", r.max_contraction_ratio)
      .set("mean_contraction_ratio", r.mean_contraction_ratio)
      .set("bound_violations", r.bound_violations)
      .set("resolved_ratios", r.ratios)
      .set("unresolved_ratios", r.unresolved_ratios)
      .set("max_coupled_residual", r.max_coupled_residual)
      .set("converged", outcome.failure.empty())
      .set("status", !outcome.failure.empty() ? "failed" : outcome.signal ? "interrupted" : "completed")
      .set("last_completed_time", outcome.completed_time)
      .set("flow_solves", st["flow"].solves + st["flow_second_pass"].solves) // both passes
      .set("mechanics_solves", st["mechanics"].solves)
      .set("monolithic_solves", st["monolithic"].solves)
      .set("newton_iterations", st["mechanics"].newton_iterations + st["monolithic"].newton_iterations)
      .set("linear_iterations", linear)
      .set("solvers", solvers)
      .set("timings", timings)
      .set("wall_time_s", outcome.wall_time)
      .set("left_out", outcome.left_out)
      .set("warnings", outcome.warnings)
      .set("mpi_ranks", outcome.ranks)
      .set("working_ranks", outcome.working_ranks);
  if (scene.coupling and scene.coupling->q_auto)
    summary.set("window_steps", window_steps_json(*scene.coupling, r));
  if (scene.adaptive)
    summary.set("adaptive", adaptive_json(*scene.adaptive, r, in.grid));
  if (!in.problem.domain.regions.names.empty())
    summary.set("regions", regions_json(in.problem.domain.regions, in.problem.materials));
  if (in.scheme.contact_pressure)
    summary.set("contact", contact_json(in.contact));
  if (const SeismicMoments m = in.scheme.seismic_moments(); !m.names.empty() and !m.steps.empty())
    summary.set("seismic_moment", seismic_moment_json(m, in.problem.domain.dim()));
  if (const auto volumes = in.scheme.fault_volumes(); !volumes.empty())
    summary.set("fault_volumes", fault_volumes_json(volumes));
  if (const auto intersections = in.scheme.fault_intersections(); !intersections.empty())
    summary.set("intersections", intersections_json(intersections));
  if (in.errors)
    summary.set("errors", errors_json(*in.errors));
  if (!outcome.failure.empty())
    summary.set("failure", outcome.failure);
  return summary;
}

} // namespace biotcontact
