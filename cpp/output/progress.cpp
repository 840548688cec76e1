#include "output/progress.h"

#include <cmath>
#include <cstdio>
#include <sstream>

namespace biotcontact
{

namespace
{
/// Seconds as a short duration: 42.1 s, 12 min 5 s, 3 h 20 min.
std::string duration(double s)
{
  char text[64];
  if (s < 60)
    std::snprintf(text, sizeof text, "%.1f s", s);
  else if (s < 3600)
    std::snprintf(text, sizeof text, "%d min %d s", int(s) / 60, int(s) % 60);
  else
    std::snprintf(text, sizeof text, "%d h %d min", int(s) / 3600, (int(s) % 3600) / 60);
  return text;
}
} // namespace

bool is_rank0(MPI_Comm comm)
{
  int rank = 0;
  MPI_Comm_rank(comm, &rank);
  return rank == 0;
}

Progress::Progress(MPI_Comm comm, double interval)
    : _root(is_rank0(comm)), _interval(interval), _start(Clock::now()), _loop_start(_start), _last_line(_start)
{
}

void Progress::say(const std::string& line)
{
  if (_root)
    std::printf("%s\n", line.c_str()), std::fflush(stdout);
  _last_line = Clock::now();
}

void Progress::start_loop(int first, int)
{
  _first = first;
  _loop_start = Clock::now();
}

void Progress::step(int step, int total, double t, int iterations, int active_nodes)
{
  const double in_loop = std::chrono::duration<double>(Clock::now() - _loop_start).count();
  const int done = step - _first;
  const double left = done > 0 ? in_loop / done * (total - step) : NAN;
  char line[320];
  std::snprintf(line, sizeof line,
                "step %4d/%d  t = %-11.5g  coupling iterations %3d  active contact nodes %d  [%s, %s left]", step,
                total, t, iterations, active_nodes, duration(elapsed()).c_str(),
                std::isfinite(left) ? duration(left).c_str() : "?");
  say(line);
}

void Progress::heartbeat(const std::string& what)
{
  if (std::chrono::duration<double>(Clock::now() - _last_line).count() >= _interval)
    say("  ... " + what + "  [" + duration(elapsed()) + "]");
}

double Progress::elapsed() const { return std::chrono::duration<double>(Clock::now() - _start).count(); }

void Progress::iteration(int step, int iteration, double dp, double du)
{
  char what[160];
  std::snprintf(what, sizeof what, "step %d: coupling iteration %d, increments dp %.3g du %.3g", step, iteration,
                dp, du);
  heartbeat(what);
}

void Progress::newton_step(int step, const std::string& system, int iteration)
{
  heartbeat("step " + std::to_string(step) + ": " + system + " contact Newton step " + std::to_string(iteration));
}

int Progress::finish(const RunEnd& end, const std::string& directory, const std::string& xdmf) const
{
  if (end.signal)
  {
    if (_root)
      std::fprintf(stderr, "biotcontact: interrupted (signal %d) after step %d, t = %g: everything up to there is in %s\n",
                   end.signal, end.completed_steps, end.completed_time, directory.c_str());
    return 128 + end.signal;
  }
  if (end.output_failed)
  {
    if (_root)
    {
      std::ostringstream kept;
      if (end.completed_steps > 0)
        kept << "steps 1 to " << end.completed_steps << ", t <= " << end.completed_time << ", are in " << directory;
      else
        kept << "no step was completed; see " << directory;
      if (end.saved > 0)
        kept << "; its last checkpoint is of step " << end.saved;
      std::fprintf(stderr, "biotcontact: error: %s (%s)\n", end.failure.c_str(), kept.str().c_str());
    }
    return run_output_failed;
  }
  if (!end.failure.empty())
  {
    if (_root)
      std::fprintf(stderr, "biotcontact: error: %s (log: %s/iterations.csv)\n", end.failure.c_str(), directory.c_str());
    return run_not_converged;
  }
  if (_root)
    std::printf("wrote %s and %s/summary.json (%f s)\n", xdmf.c_str(), directory.c_str(), elapsed()), std::fflush(stdout);
  return run_ok;
}

} // namespace biotcontact
