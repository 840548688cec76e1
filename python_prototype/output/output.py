"""Output of a run (cpp/output/output.cpp): the XDMF time series (time_series.py),
iterations.csv and summary.json. Rows and times are flushed as they are written, so a run that
stops later loses nothing it finished."""
import math
import os
import time

import numpy as np

from ..scene.scene import agree_on_error
from .progress import is_rank0
from .time_series import TimeSeries
from .write_failure import OutputError, agree_on_output_error, write_failure_reason

COLUMNS = ("step,time,iteration,dsigma_norm,ratio,gamma,dp_norm,du_norm,active_nodes,fault_dp_norm,fault_ratio,"
           "newton_steps")


def number(v):
    """As the C++ writes doubles: 17 significant digits."""
    return f"{v:.17g}"


def to_json(value, indent=0):
    """JSON in the C++ layout (insertion order, 2-space indent, null for NaN/inf)."""
    if isinstance(value, dict):
        pad = " " * (indent + 2)
        items = [f'{pad}"{k}": {to_json(v, indent + 2)}' for k, v in value.items()]
        return "{\n" + ",\n".join(items) + "\n" + " " * indent + "}"
    if isinstance(value, (bool, np.bool_)):
        return "true" if value else "false"
    if isinstance(value, (int, np.integer)):
        return str(value)
    if isinstance(value, (float, np.floating)):
        return number(value) if math.isfinite(value) else "null"
    if isinstance(value, (list, tuple, np.ndarray)):  # on one line, as the C++ writes an array
        return "[" + ", ".join(to_json(v, indent) for v in value) + "]"
    return '"' + str(value).replace("\\", "\\\\").replace('"', '\\"') + '"'


class Output:
    def __init__(self, comm, directory, mesh, xdmf, resume=None):
        """Creates the files; or, given the position() of an earlier run of
        the same scene, goes on in its files, dropping what came after it."""
        self.comm, self._directory, self.time = comm, directory, 0.0
        self.csv, self.failed = None, False
        # Rank 0 makes the directory; every rank learns whether it could.
        error = ""
        if is_rank0(comm):
            try:
                os.makedirs(directory, exist_ok=True)
            except OSError as e:
                error = f"--out {directory}: cannot create the output directory: {e.strerror}"
            else:
                path = os.path.join(directory, "iterations.csv")
                try:
                    if resume is not None:  # the position starts with the length of iterations.csv
                        os.truncate(path, int(resume.split("\n", 1)[0]))
                    self.csv = open(path, "a" if resume is not None else "w")
                except OSError:
                    error = f"--out {directory}: cannot write iterations.csv there"
                else:
                    if resume is None:
                        self.csv.write(COLUMNS + "\n")
                        self.csv.flush()
        agree_on_error(error, comm)
        series = resume.split("\n", 1)[1] if resume is not None else None
        failed, self.xdmf = "", None
        try:
            self.xdmf = TimeSeries(comm, self.xdmf_path(), mesh, series) if xdmf else None
        except OutputError as e:
            failed = str(e)
        agree_on_output_error(failed, comm)

    def _agree(self, failed):
        """agree_on_output_error, remembering a failure: the files are then
        closed without the writes a full disk refused (close)."""
        try:
            agree_on_output_error(failed, self.comm)
        except OutputError:
            self.failed = True
            raise

    def position(self):
        """Where the files stand, for a checkpoint (this rank's view)."""
        return f"{self.csv.tell() if self.csv else 0}\n" + (self.xdmf.position() if self.xdmf else "")

    def xdmf_path(self):
        return os.path.join(self._directory, "solution.xdmf")

    def directory(self):
        return self._directory

    def _cannot_write(self, path, error):
        return f"cannot write {path}: {write_failure_reason(self._directory, error)}"

    def write(self, f, t):
        """Raises OutputError on every rank when any rank failed."""
        if self.xdmf is None:
            return
        start = time.perf_counter()
        failed = ""
        try:
            self.xdmf.write(f, t)
        except OutputError as e:
            failed = str(e)
        self._agree(failed)
        self.time += time.perf_counter() - start

    def iteration(self, r):
        """Writes the IterationRecord `r` (coupling.py) as a row of iterations.csv."""
        failed = ""
        if self.csv is not None:
            v = [number(x) if math.isfinite(x) else "" for x in (r.dsigma_norm, r.ratio, r.gamma, r.dp_norm, r.du_norm)]
            try:
                f = [number(x) if math.isfinite(x) else "" for x in (r.fault_dp_norm, r.fault_ratio)]
                self.csv.write(f"{r.step},{number(r.time)},{r.iteration},{','.join(v)},{r.active_nodes},"
                               f"{','.join(f)},{r.newton_steps}\n")
                self.csv.flush()
            except OSError as e:
                failed = self._cannot_write(self.csv.name, e)
        self._agree(failed)

    def summary(self, summary):
        """Written beside and renamed: a full disk leaves the old one or
        none, never half of one."""
        failed = ""
        if is_rank0(self.comm):
            path = os.path.join(self._directory, "summary.json")
            try:
                with open(path + ".new", "w") as f:
                    f.write(to_json(summary) + "\n")
                os.replace(path + ".new", path)
            except OSError as e:
                failed = self._cannot_write(path, e)
                if os.path.exists(path + ".new"):
                    os.remove(path + ".new")
        self._agree(failed)

    def close(self):
        if self.xdmf is not None:
            # After any failed write the disk may be full: closing the HDF5
            # file would write metadata that cannot fit (TimeSeries.close).
            self.xdmf.failed = self.xdmf.failed or self.failed
            self.xdmf.close()
        if self.csv is not None:
            try:
                self.csv.close()
            except OSError:
                pass  # every row is flushed as written: what close could not flush was a failed write, reported
