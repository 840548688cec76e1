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
