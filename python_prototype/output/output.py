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

COLUMNS = "step,time,iteration,dsigma_norm,ratio,gamma,dp_norm,du_norm,active_nodes"


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
    return '"' + str(value).replace("\\", "\\\\").replace('"', '\\"') + '"'


class Output:
    def __init__(self, comm, directory, mesh, xdmf, resume=None):
        """Creates the files; or, given the position() of an earlier run of
        the same scene, goes on in its files, dropping what came after it."""
        self.comm, self._directory, self.time = comm, directory, 0.0
        self.csv = None
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
        self.xdmf = TimeSeries(comm, self.xdmf_path(), mesh, series) if xdmf else None

    def position(self):
        """Where the files stand, for a checkpoint (this rank's view)."""
        return f"{self.csv.tell() if self.csv else 0}\n" + (self.xdmf.position() if self.xdmf else "")

    def xdmf_path(self):
        return os.path.join(self._directory, "solution.xdmf")

    def write(self, f, t):
        if self.xdmf is None:
            return
        start = time.perf_counter()
        self.xdmf.write(f, t)
        self.time += time.perf_counter() - start

    def iteration(self, step, t, iteration, dsigma, ratio, gamma, dp_norm, du_norm, active_nodes):
        if self.csv is None:
            return
        v = [number(x) if math.isfinite(x) else "" for x in (dsigma, ratio, gamma, dp_norm, du_norm)]
        self.csv.write(f"{step},{number(t)},{iteration},{','.join(v)},{active_nodes}\n")
        self.csv.flush()

    def summary(self, summary):
        if is_rank0(self.comm):
            with open(os.path.join(self._directory, "summary.json"), "w") as f:
                f.write(to_json(summary) + "\n")

    def close(self):
        if self.xdmf is not None:
            self.xdmf.close()
        if self.csv is not None:
            self.csv.close()
