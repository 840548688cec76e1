// The interface of a step, whichever system it solves (the flow, the
// mechanics, or flow and mechanics together): what the schemes, checkpoints
// and the output ask of any step, so that none of them branches on which
// physics a scene has.
#pragma once

#include "assembly/linear_algebra.h"
#include "assembly/petsc_error.h"
#include "contact/contact.h"
#include "steps/solve_record.h"
#include "steps/system.h"
#include "time/time_scheme.h"

#include <dolfinx/fem/Function.h>
#include <span>
#include <string>
#include <utility>
#include <vector>

namespace biotcontact
{

/// @brief The state of a step at its start: its unknowns, to go back to
/// when the step is retried, and its pressure and displacement (empty where
/// it has none), BDF2's memory once the step is accepted.
struct StepState
{
  std::vector<double> unknowns, p, u;
};

/// The functions of a step that a checkpoint keeps besides its unknowns
/// (the time scheme's memory), by checkpoint name.
using History = std::vector<std::pair<std::string, dolfinx::fem::Function<double>*>>;

/// @brief One step of a time-stepping scheme on one system: advances its
/// unknowns from t_{k-1} to t_k.
///
/// A scheme with one solve per step (coupling/single_solve.h) drives any
/// step through advance(); the fixed-stress split drives the flow and the
/// mechanics step through their own interfaces, which iterate between them.
class Step
{
public:
  virtual ~Step() = default;

  /// The system's name in summary.json and in checkpoints.
  virtual std::string name() const = 0;
  virtual const System& system() const = 0;
  virtual System& system() = 0;

  /// Solves the step to time t with the time derivative `d`
  /// (time/time_scheme.h) from the state the step holds.
  virtual void advance(double t, const TimeDerivative& d) = 0;
  /// The "dt" constant changed (parameters.h, set_time_step): rebuilds what
  /// depends on it.
  virtual void time_step_changed() {}
  /// mechanics.initial_equilibrium: replaces u = 0 by the displacement in
  /// equilibrium with the loads at t = 0 and the initial pressure (nothing
  /// for a step without mechanics); what its solve measured (its rows of
  /// iterations.csv at step 0).
  virtual std::vector<SolveRecord> equilibrate() { return {}; }

  /// A time step (or a window of the fixed-stress split) starts from the
  /// current unknowns: friction measures its slip increments from them, a
  /// conduit fault its pressure's change (nothing without either).
  virtual void begin_step() {}

  /// The state now (at the start of a step), and going back to it.
  virtual StepState state() const = 0;
  virtual void restore(const StepState& start) = 0;
  /// The step from `start` was accepted: it becomes the state one step
  /// before the next (BDF2's memory).
  virtual void keep_history(const StepState&) {}
  /// The step's solution at t (loaded in the step) was accepted: what the
  /// step adds up over the run takes it (a conduit fault's volumes).
  virtual void accept(double) {}
  /// Whether the step's solution at t (loaded in the step) conserves what
  /// it must to be accepted: one line naming what does not (a conduit
  /// fault whose volumes do not balance), empty when all does.
  virtual std::string unbalanced(double) const { return {}; }
  /// What each solve of the last advance measured, in order, also when it
  /// failed: one record, or one per iteration of the monolithic step on its
  /// conduit faults' apertures (iterations.csv).
  const std::vector<SolveRecord>& solves() const { return _solves; }
  /// The solves of the last advance, which the progress line shows.
  int iterations() const { return static_cast<int>(_solves.size()); }

  /// The unknowns, their fields (for checkpoints) and their restoration.
  virtual std::span<const double> unknowns() const = 0;
  virtual void set_unknowns(std::span<const double> x) = 0;
  virtual std::vector<UnknownsPart> parts() const = 0;
  /// The time scheme's memory a checkpoint keeps (empty by default).
  virtual History history() const { return {}; }
  /// State in plain arrays, the same on every rank, that a checkpoint keeps
  /// (the conduit faults' pressure; empty by default; collective), and its
  /// restoration.
  virtual std::map<std::string, std::vector<double>> arrays() const { return {}; }
  virtual void restore_arrays(const std::map<std::string, std::vector<double>>&) {}

  /// The pressure and the displacement now (empty where the step has none).
  virtual std::span<const double> pressure_values() const { return {}; }
  virtual std::span<const double> displacement_values() const { return {}; }

  /// Whether the contact active set is `before` (collective; true without
  /// contact).
  virtual bool same_contact_set(const ActiveSet&) { return true; }
  /// The contact active set now (empty without contact; collective).
  virtual ActiveSet active_contact_set() { return {}; }

  double assembly_time = 0; // right-hand sides

protected:
  /// The fields the step's solves move (p, u, p_f), for their records.
  virtual SolveFields solve_fields() const = 0;
  /// Brackets each solve of advance(); the first of an advance clears the
  /// last one's records (collective: the record counts active nodes).
  void solve_begins(bool first)
  {
    if (first)
      _solves.clear();
    _meter.start(solve_fields(), system().newton_steps());
  }
  void solve_ends() { _solves.push_back(_meter.record(solve_fields(), system().newton_steps(), active_contact_set().nodes)); }
  /// Runs `solve` as one solve of advance(), between solve_begins(first)
  /// and solve_ends(); one that fails (SolverError) leaves its record too,
  /// its Newton steps and no change, before its error goes on: the rows of
  /// iterations.csv show what a failed step spent.
  template <typename Solve>
  void recorded_solve(bool first, Solve&& solve)
  {
    solve_begins(first);
    try
    {
      solve();
    }
    catch (const SolverError&)
    {
      _solves.push_back(_meter.failed(system().newton_steps(), active_contact_set().nodes));
      throw;
    }
    solve_ends();
  }

private:
  SolveMeter _meter;
  std::vector<SolveRecord> _solves;
};

} // namespace biotcontact
