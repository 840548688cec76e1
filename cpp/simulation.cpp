#include "simulation.h"

#include "coupling/contraction.h"
#include "coupling/fallback.h"
#include "coupling/scheme.h"
#include "diagnostics/closed_form.h"
#include "diagnostics/description.h"
#include "diagnostics/reference_errors.h"
#include "domain/create_domain.h"
#include "domain/mesh_checks.h"
#include "domain/working_ranks.h"
#include "output/checkpoint.h"
#include "output/directory_lock.h"
#include "output/fields.h"
#include "output/interruption.h"
#include "output/progress.h"
#include "output/summary.h"

#include <filesystem>
#include <optional>
#include <sstream>

namespace biotcontact
{

namespace
{

/// @brief One run of a scene, in the order of its story: set up the problem
/// (mesh, forms, materials), describe it, make the scheme and its steps,
/// open the output, start or restore, the time loop, the summary and the
/// exit status.
class Simulation
{
public:
  Simulation(const Scene& scene, const std::string& directory, MPI_Comm comm, const RunControl& control)
      : _scene(with_mandel_plate(scene)), _directory(directory), _world(comm), _comm(comm), _control(control),
        _progress(comm, scene.progress_interval)
  {
  }

  int run()
  {
    set_up();
    if (!_domain->mesh)
      return 0; // this rank waits; main takes rank 0's status
    _scheme = std::make_unique<Scheme>(*_problem);
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
    catch (const SolverError& e) // the initial equilibrium (start_or_restore)
    {
      _end.failure = e.what();
    }
    write_summary();
    return exit_status();
  }

private:
  void set_up();
  void open_output();
  void equilibrate();
  void start_or_restore();
  WindowObserver observer();
  void report_newton_steps(Scheme& scheme);
  void time_loop();
  bool falls_back() const;
  bool fall_back();
  bool fallback_failed(const std::string& why);
  SolvedStep solve_by_fallback();
  std::string step_being_computed() const;
  int planned_steps() const;
  void output_failed(const OutputError& e);
  bool stop();
  void save_completed();
  void save_on_failure();
  void write_summary();
  int exit_status() const;
  RunState run_state() { return {*_scheme, *_domain->mesh, _report, _state, _grid}; }

  const Scene _scene; // as read, with a closed form's boundary values imposed
  const std::string _directory;
  MPI_Comm _world; // the ranks started
  MPI_Comm _comm;  // those that work (domain/working_ranks.h)
  const RunControl& _control;
  Progress _progress;
  std::optional<Domain> _domain;
  Parameters _parameters; // of the top-level material; gamma the largest of any cell
  Materials _materials;
  Constants _constants;
  std::optional<Problem> _problem; // the parts above, with the scene and the forms
  Description _description;
  std::unique_ptr<Scheme> _scheme;
  std::unique_ptr<MonolithicFallback> _fallback; // coupling.fallback, from the split's first failed step
  std::optional<Checkpoint> _resumed;
  std::optional<Checkpoint> _completed; // the last completed step's, with output.checkpoint_every or
                                        // coupling.fallback
  std::optional<DirectoryLock> _lock;
  std::unique_ptr<Output> _output;
  std::unique_ptr<OutputFields> _fields;
  TimeGrid _grid;
  CouplingReport _report;
  ControllerState _state;
  RunEnd _end;                 // the steps completed and saved so far; why the run stopped
  bool _checkpointing = false; // writing the checkpoint of the last completed step
};

/// The problem: the mesh and its tags, the compiled forms of its cell type,
/// the materials of its cells, the derived parameters and the constants of
/// the forms; then what the scene leaves out, and warnings where the method
/// is known to degrade (diagnostics/description.h).
void Simulation::set_up()
{
  _domain.emplace(create_domain(_scene, _comm));
  if (!_domain->mesh)
    return;
  const std::string ranks = working_ranks_line(_comm, *_domain->mesh, _scene.solver.cells_per_rank);
  _comm = _domain->mesh->comm(); // the working ranks
  check_expressions(_scene, *_domain, _comm);
  const CompiledForms& forms = compiled_forms(_domain->mesh->topology().cell_type());
  _materials = make_materials(_scene, *_domain, forms);
  _parameters = derive_parameters(_scene);
  _parameters.gamma = _materials.gamma;
  _constants = make_constants(_scene, _parameters);
  _problem.emplace(Problem{_scene, *_domain, forms, _materials, _parameters, _constants});
  _description = describe(*_problem);
  if (!ranks.empty())
    _description.lines.push_back(ranks);
  for (const std::string& line : _description.lines)
    _progress.say(line);
}

/// The time grid, the checkpoint a restart goes on from (loaded into the
/// steps), the output files (created, or those of the checkpoint's run) and
/// the fields written into them.
void Simulation::open_output()
{
  // The lock first: nothing in the directory is read, created or truncated
  // while another run holds it. A restart of a directory that does not
  // exist is refused by read_checkpoint, without creating it. Rank 0's view
  // decides for all (ranks may see a file system differently), so that every
  // rank meets the same collectives next.
  int locks = !_control.restart or std::filesystem::is_directory(_directory);
  MPI_Bcast(&locks, 1, MPI_INT, 0, _comm);
  if (locks)
    _lock.emplace(_comm, _directory);
  _grid = time_grid(_scene); // a retry (time.retry) halves some of its steps
  if (_control.restart)
  {
    // Loaded before the files are opened: a checkpoint that does not match
    // is refused with the files as they were.
    _resumed = read_checkpoint(_comm, _directory, _control.fingerprint);
    restore_checkpoint(*_resumed, run_state(), _comm, _directory);
  }
  _output = std::make_unique<Output>(_comm, _directory, _domain->mesh, _scene.write_xdmf,
                                     _resumed ? &_resumed->output : nullptr);
  _fields = std::make_unique<OutputFields>(*_problem, *_scheme, *_output, _resumed ? &_resumed->time : nullptr);
}

/// mechanics.initial_equilibrium: the solve at t = 0, a row of
/// iterations.csv at step 0 for each solve (its contact solve's Newton steps).
void Simulation::equilibrate()
{
  const double nan = SolveRecord::none;
  int i = 0;
  try
  {
    for (Step* step : _scheme->steps())
      for (const SolveRecord& s : step->equilibrate())
        _output->iteration({0, 0.0, ++i, nan, nan, nan, relative(s.dp, s.p), relative(s.du, s.u), s.active_nodes, nan,
                            nan, s.newton_steps});
  }
  catch (const SolverError& e)
  {
    throw SolverError("the initial equilibrium (t = 0): " + std::string(e.what()));
  }
}

/// The initial state, written at t = 0, or the checkpoint's step and time.
void Simulation::start_or_restore()
{
  if (_resumed)
  {
    _end.saved = _end.completed_steps = _resumed->steps;
    _end.completed_time = _resumed->time;
    if (_scheme->u)
      _fields->contact = _scheme->contact_state();
    _progress.say("restarted from the checkpoint at step " + std::to_string(_end.completed_steps) + ", t = "
                  + std::to_string(_end.completed_time));
    return;
  }
  if (_scene.mechanics and _scene.mechanics->initial_equilibrium)
    equilibrate();
  _fields->write_flow(0.0);
  if (_scheme->u)
    _fields->write_mechanics(0.0);
  if (_scheme->contact_boundary)
    _output->write(*_scheme->contact_boundary, 0.0); // once: every later time repeats it
  _scheme->start(_state);
}

/// After each completed (and written) step: a checkpoint every
/// checkpoint_every steps and at an interruption; then whether to stop.
/// The last completed step is kept in memory too: a step that fails writes
/// it (save_completed).
bool Simulation::stop()
{
  if (_scene.checkpoint_every > 0 or falls_back())
    _completed = capture_checkpoint(run_state(), _end.completed_steps, _end.completed_time, _output->position());
  if (_scene.checkpoint_every > 0 and _end.completed_steps % _scene.checkpoint_every == 0)
    save_completed();
  _end.signal = interruption_signal(_comm);
  if (_end.signal and _scene.checkpoint_every > 0 and _end.saved != _end.completed_steps)
    save_completed();
  return _end.signal != 0;
}

/// Writes the checkpoint of the last completed step.
void Simulation::save_completed()
{
  _checkpointing = true;
  write_checkpoint(_comm, _directory, _control.fingerprint, *_completed);
  _checkpointing = false;
  _end.saved = _completed->steps;
}

/// A step failed: the checkpoint of the last completed one, where the run
/// writes checkpoints and has not written it, so that nothing it finished
/// is lost and a restart goes on from there (restart_proposal).
void Simulation::save_on_failure()
{
  if (!_completed or _scene.checkpoint_every == 0)
    return;
  try
  {
    if (_end.saved != _completed->steps)
      save_completed();
    _end.failure += "; step " + std::to_string(_completed->steps) + " is in the checkpoint (--restart " + _directory
                    + restart_proposal(_end.failure, _scene) + " goes on from it)";
  }
  catch (const OutputError& e)
  {
    _checkpointing = false;
    _end.failure += "; the checkpoint of step " + std::to_string(_completed->steps) + " could not be written: "
                    + e.what();
  }
}

/// What the coupling schemes tell the run: write each step, print the
/// progress, log each iteration, checkpoint, stop at an interruption.
WindowObserver Simulation::observer()
{
  WindowObserver o;
  o.flow_state = [this](double t) { if (_scene.is_output_time(t)) _fields->write_flow(t); };
  o.mechanics_state = [this](double t, int step, int iterations)
  {
    if (_scheme->u and _scene.is_output_time(t))
      _fields->write_mechanics(t);
    else if (_scheme->u)
      _fields->read_contact();
    _end.completed_steps = step;
    _end.completed_time = t;
    _progress.step(step, planned_steps(), t, iterations, _fields->contact.active_nodes);
  };
  o.stop = [this] { return stop(); };
  o.retry = [this](const std::string& message) { _progress.say(message); };
  o.note = o.retry;
  o.iteration = [this](int step, int iteration, double dp, double du)
  { _progress.iteration(step, iteration, dp, du); };
  o.record = [this](const IterationRecord& r) { _output->iteration(r); };
  return o;
}

/// A contact solve of `scheme` longer than 10 s (a large monolithic step)
/// prints its Newton steps as it goes, like the coupling iterations of the
/// split.
void Simulation::report_newton_steps(Scheme& scheme)
{
  scheme.on_newton_step([this](const std::string& system, int iteration)
                        { _progress.newton_step(_end.completed_steps + 1, system, iteration); });
}

/// The steps from t = 0 (or the checkpoint) to the end, driven by the
/// scheme. A failure ends the loop with what was finished written; it names
/// the step it was computing. With coupling.fallback the monolithic scheme
/// solves a step the split failed at, and the split goes on from it.
void Simulation::time_loop()
{
  const WindowObserver o = observer();
  report_newton_steps(*_scheme);
  _progress.start_loop(_end.completed_steps, planned_steps());
  if (falls_back())
    _completed = capture_checkpoint(run_state(), _end.completed_steps, _end.completed_time, _output->position());
  CouplingRun run{_grid, _scheme->step_control.get(), o, _report, _state};
  do
  {
    try
    {
      _scheme->run(run);
      break;
    }
    catch (const CouplingError& e)
    {
      _end.failure = e.what(); // names its step and the last increments
    }
    catch (const SolverError& e)
    {
      _end.failure = step_being_computed() + ": " + e.what();
      _report.windows = _end.completed_steps;
    }
  } while (fall_back());
  if (!_end.failure.empty())
  {
    save_on_failure();
    _fields->contact = _scheme->contact_state(); // at the failure
  }
}

bool Simulation::falls_back() const
{
  return _scene.coupling and _scene.coupling->fallback == Fallback::monolithic;
}

/// coupling.fallback: after the split failed at a step (_end.failure), the
/// monolithic scheme solves it from the last completed step, and the split
/// takes its state (restore_run_state, as a restart with another
/// coupling.scheme); the step is written and counted (fallback_steps).
/// Returns whether the split goes on: not when the run has no fallback,
/// the monolithic solve fails too (the failure says both) or the run is
/// interrupted.
bool Simulation::fall_back()
{
  if (!falls_back() or !_completed)
    return false;
  _progress.say(_end.failure + "; the monolithic scheme solves the step (coupling.fallback)");
  SolvedStep solved;
  try
  {
    solved = solve_by_fallback();
  }
  catch (const CouplingError& e)
  {
    return fallback_failed(e.what());
  }
  catch (const SolverError& e)
  {
    return fallback_failed(e.what());
  }
  _end.failure.clear();
  ++_report.fallback_steps;
  // The step's fields are the monolithic scheme's, which solved it.
  const WindowObserver o = observer();
  _fields->read_from(*_fallback->scheme);
  o.flow_state(solved.t);
  o.mechanics_state(solved.t, solved.step, solved.iterations);
  _fields->read_from(*_scheme);
  return !o.stop();
}

/// The monolithic scheme failed at the step too: the failure says both,
/// and the split's state is the last completed step's.
bool Simulation::fallback_failed(const std::string& why)
{
  _end.failure += "; the monolithic scheme failed there too (coupling.fallback): " + why;
  restore_run_state(*_completed, run_state(), _comm, _directory);
  return false;
}

/// The monolithic scheme's steps from the last completed one to the end of
/// the split's failed step, its state then the split's. A multirate
/// window's q fine steps are q monolithic steps, each a window of one fine
/// step for the history the split goes on from (WindowHistory::start);
/// their rows in iterations.csv and the step in the progress are the
/// window's (fallback_observer). Stops at the window's end time: a retry
/// of the monolithic scheme halves steps within it.
SolvedStep Simulation::solve_by_fallback()
{
  if (!_fallback)
  {
    _fallback = std::make_unique<MonolithicFallback>(*_problem);
    report_newton_steps(*_fallback->scheme);
  }
  Scheme& m = *_fallback->scheme;
  const RunState monolithic{m, *_domain->mesh, _report, _state, _grid};
  restore_run_state(*_completed, monolithic, _comm, _directory);
  const double end = _grid.t[std::min<std::size_t>(_report.fine_steps + _parameters.q, _grid.t.size() - 1)];
  SolvedStep solved{_report.windows + 1};
  _report.windows = static_cast<int>(_report.fine_steps); // the monolithic scheme's steps are fine steps
  const WindowObserver split = observer();
  const WindowObserver o = fallback_observer(split, solved, end,
                                             [&](double t)
                                             {
                                               _fields->read_from(m);
                                               split.flow_state(t);
                                               _fields->read_from(*_scheme);
                                             });
  CouplingRun run{_grid, m.step_control.get(), o, _report, _state};
  m.run(run);
  _report.windows = solved.step;
  _state.q_limit = 1; // coupling.q = "auto": the next window starts short, as after a contact change
  Checkpoint c = capture_checkpoint(monolithic, solved.step, solved.t, _output->position());
  // With backward Euler the monolithic scheme keeps no displacement one
  // step before; q = "auto" reads it: the start of its one fine step.
  c.fields.try_emplace("displacement_before", _completed->fields.at("displacement"));
  restore_run_state(c, run_state(), _comm, _directory);
  return solved;
}

/// The mechanics steps (windows) of the run, for the progress: with
/// coupling.q = "auto" those done and the rest at the last window's q.
int Simulation::planned_steps() const
{
  const bool q_auto = _scene.coupling and _scene.coupling->q_auto;
  const int q = q_auto and _state.window_q > 0 ? _state.window_q : _parameters.q;
  return _report.windows + static_cast<int>((_grid.steps() - _report.fine_steps + q - 1) / q);
}

/// "step N (t = T)" of the step after the last completed one.
std::string Simulation::step_being_computed() const
{
  const int step = _end.completed_steps + 1;
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
  const std::string when = !_fields       ? "opening the output" // solution.xdmf, or fault.xdmf after it
                           : _checkpointing ? "after step " + std::to_string(_end.completed_steps)
                                            : step_being_computed();
  _end.failure = when + ": " + e.what();
  _end.output_failed = true;
  _report.windows = _end.completed_steps;
}

/// summary.json (output/summary.h), whatever the run's end (when the disk
/// is full, as far as it can be written).
void Simulation::write_summary()
{
  if (!_output)
    return;
  const ContactState none; // no fields where the output files could not be made
  SummaryInput in{*_problem, *_scheme, _report, _grid, _fields ? _fields->contact : none, std::nullopt};
  if (_fallback)
    in.fallback = _fallback->scheme.get();
  if (_scene.reference and _end.failure.empty() and _end.signal == 0)
    in.errors = reference_errors(*_problem, _scheme->u, _scheme->p);
  int working = 1, ranks = 1;
  MPI_Comm_size(_comm, &working);
  MPI_Comm_size(_world, &ranks);
  const RunOutcome outcome{_end.failure,         _end.signal,       _end.completed_time,
                           _description.left_out, _description.warnings, _progress.elapsed(),
                           _output->time,         ranks,              working};
  try
  {
    _output->summary(run_summary(in, outcome));
  }
  catch (const OutputError& e)
  {
    if (_end.output_failed)
      _end.failure += "; summary.json could not be written either";
    else
      output_failed(e);
  }
}

/// The last line and the exit status (output/progress.h).
int Simulation::exit_status() const
{
  return _progress.finish(_end, _directory, _output ? _output->xdmf_path() : std::string());
}

} // namespace

int run(const Scene& scene, const std::string& directory, MPI_Comm comm, const RunControl& control)
{
  return Simulation(scene, directory, comm, control).run();
}

} // namespace biotcontact
