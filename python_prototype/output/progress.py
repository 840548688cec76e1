"""What a run prints while it runs (cpp/output/progress.h): one line per
completed step with the wall time so far and an estimate of the time left,
and a line every 10 s (output.progress_interval) within a step that runs
longer, so that a long 3D run never looks hung; and the run's last line
and exit status."""
import math
import sys
import time
from dataclasses import dataclass

# Exit status of a run.
RUN_OK, RUN_NOT_CONVERGED, RUN_OUTPUT_FAILED = 0, 3, 4


@dataclass
class RunEnd:
    """How a run ended, for its last line: why it failed (empty when it did
    not; output_failed when a file could not be written), the interruption's
    signal, the last completed and the last checkpointed step."""
    failure: str = ""
    output_failed: bool = False
    signal: int = 0
    completed_steps: int = 0
    completed_time: float = 0.0
    saved: int = 0


def is_rank0(comm):
    """Whether this process is rank 0 of comm (the one that prints)."""
    return comm.rank == 0


def _duration(s):
    """Seconds as a short duration: 42.1 s, 12 min 5 s, 3 h 20 min."""
    if s < 60:
        return f"{s:.1f} s"
    if s < 3600:
        return f"{int(s) // 60} min {int(s) % 60} s"
    return f"{int(s) // 3600} h {(int(s) % 3600) // 60} min"


class Progress:
    """The console progress of a run (rank 0 prints, every rank may call).

    The estimate of the time left assumes the remaining steps cost what the
    steps of this run have cost on average: (elapsed in the time loop / steps
    done in it) x steps left."""

    def __init__(self, comm, interval):
        """`interval`: the seconds between the lines within a step."""
        self._root, self._interval = is_rank0(comm), interval
        self._start = self._loop_start = self._last_line = time.perf_counter()
        self._first = 0

    def say(self, line):
        """A line, as it is (rank 0), flushed at once."""
        if self._root:
            print(line, flush=True)
        self._last_line = time.perf_counter()

    def start_loop(self, first, total):
        """The time loop starts at step `first` of `total` (a restart: first > 0)."""
        self._first = first
        self._loop_start = time.perf_counter()

    def step(self, step, total, t, iterations, active_nodes):
        """Step `step` of `total` (total may grow: time.retry) ended at time t."""
        in_loop = time.perf_counter() - self._loop_start
        done = step - self._first
        left = in_loop / done * (total - step) if done > 0 else math.nan
        self.say(f"step {step:4d}/{total}  t = {t:<11.5g}  coupling iterations {iterations:3d}  "
                 f"active contact nodes {active_nodes}  "
                 f"[{_duration(self.elapsed())}, {_duration(left) if math.isfinite(left) else '?'} left]")

    def heartbeat(self, what):
        """Within a step: prints `what` when the interval has passed since the last line."""
        if time.perf_counter() - self._last_line >= self._interval:
            self.say(f"  ... {what}  [{_duration(self.elapsed())}]")

    def iteration(self, step, iteration, dp, du):
        """The heartbeat of coupling iteration `iteration` of step `step`,
        with its increments."""
        self.heartbeat(f"step {step}: coupling iteration {iteration}, increments dp {dp:.3g} du {du:.3g}")

    def newton_step(self, step, system, iteration):
        """The heartbeat of Newton step `iteration` of `system`'s contact
        solve in step `step`."""
        self.heartbeat(f"step {step}: {system} contact Newton step {iteration}")

    def finish(self, end, directory, xdmf):
        """Prints the run's last line (what it wrote into `directory`, or why
        it stopped: to stderr) for the RunEnd `end` and returns its exit
        status (RUN_OK, RUN_NOT_CONVERGED, RUN_OUTPUT_FAILED, or 128 + the
        signal of an interruption)."""
        if end.signal:
            if self._root:
                print(f"biotcontact: interrupted (signal {end.signal}) after step {end.completed_steps}, "
                      f"t = {end.completed_time:g}: everything up to there is in {directory}",
                      file=sys.stderr, flush=True)
            return 128 + end.signal
        if end.output_failed:
            if self._root:
                kept = (f"steps 1 to {end.completed_steps}, t <= {end.completed_time:g}, are in {directory}"
                        if end.completed_steps > 0 else f"no step was completed; see {directory}")
                checkpoint = f"; its last checkpoint is of step {end.saved}" if end.saved > 0 else ""
                print(f"biotcontact: error: {end.failure} ({kept}{checkpoint})", file=sys.stderr, flush=True)
            return RUN_OUTPUT_FAILED
        if end.failure:
            if self._root:
                print(f"biotcontact: error: {end.failure} (log: {directory}/iterations.csv)", file=sys.stderr,
                      flush=True)
            return RUN_NOT_CONVERGED
        if self._root:
            print(f"wrote {xdmf} and {directory}/summary.json ({self.elapsed():f} s)", flush=True)
        return RUN_OK

    def elapsed(self):
        """Seconds since the run started."""
        return time.perf_counter() - self._start
