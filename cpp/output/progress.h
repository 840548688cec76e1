// What a run prints while it runs: one line per completed step with the wall
// time so far and an estimate of the time left, and a line every 10 s
// (output.progress_interval) within a step that runs longer, so that a long
// 3D run never looks hung.
#pragma once

#include <chrono>
#include <mpi.h>
#include <string>

namespace biotcontact
{

/// Exit status of a run.
enum RunStatus
{
  run_ok = 0,
  run_not_converged = 3,
  run_output_failed = 4,
};

/// @brief How a run ended, for its last line: why it failed (empty when
/// it did not; output_failed when a file could not be written), the
/// interruption's signal, the last completed and the last checkpointed step.
struct RunEnd
{
  std::string failure;
  bool output_failed = false;
  int signal = 0;
  int completed_steps = 0;
  double completed_time = 0;
  int saved = 0;
};

/// Whether this process is rank 0 of comm (the one that prints).
bool is_rank0(MPI_Comm comm);

/// @brief The console progress of a run (rank 0 prints, every rank may call).
///
/// The estimate of the time left assumes the remaining steps cost what the
/// steps of this run have cost on average: (elapsed in the time loop / steps
/// done in it) x steps left.
class Progress
{
public:
  /// `interval`: the seconds between the lines within a step.
  Progress(MPI_Comm comm, double interval);

  /// A line, as it is (rank 0), flushed at once.
  void say(const std::string& line);

  /// The time loop starts at step `first` of `total` (a restart: first > 0).
  void start_loop(int first, int total);

  /// Step `step` of `total` (total may grow: time.retry) ended at time t.
  void step(int step, int total, double t, int iterations, int active_nodes);

  /// Within a step: prints `what` when the interval has passed since the last line.
  void heartbeat(const std::string& what);
  /// The heartbeat of coupling iteration `iteration` of step `step`, with
  /// its increments.
  void iteration(int step, int iteration, double dp, double du);

  /// The heartbeat of Newton step `iteration` of `system`'s contact solve
  /// in step `step`.
  void newton_step(int step, const std::string& system, int iteration);

  /// Prints the run's last line (what it wrote into `directory`, or why it
  /// stopped: to stderr) and returns its exit status (RunStatus, or 128 +
  /// the signal of an interruption).
  int finish(const RunEnd& end, const std::string& directory, const std::string& xdmf) const;

  /// Seconds since the run started.
  double elapsed() const;

private:
  using Clock = std::chrono::steady_clock;
  bool _root;
  double _interval;
  Clock::time_point _start, _loop_start, _last_line;
  int _first = 0;
};

} // namespace biotcontact
