"""What a run prints while it runs (cpp/output/progress.h): one line per
completed step with the wall time so far and an estimate of the time left,
and a line every 10 s (output.progress_interval) within a step that runs
longer, so that a long 3D run never looks hung."""
import math
import time


def is_rank0(comm):
    """Whether this process is rank 0 of comm (the one that prints)."""
    return comm.rank == 0


def duration(s):
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
                 f"[{duration(self.elapsed())}, {duration(left) if math.isfinite(left) else '?'} left]")

    def heartbeat(self, what):
        """Within a step: prints `what` when the interval has passed since the last line."""
        if time.perf_counter() - self._last_line >= self._interval:
            self.say(f"  ... {what}  [{duration(self.elapsed())}]")

    def elapsed(self):
        """Seconds since the run started."""
        return time.perf_counter() - self._start
