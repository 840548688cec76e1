"""Checkpoint and restart (cpp/output/checkpoint.h): the state a run needs to
continue after its last completed step, written every N steps
(output.checkpoint_every) and when the run is interrupted; `run SCENE
--restart DIR` goes on in the same files. Each rank writes its own local
arrays (ghosts included) to DIR/checkpoint/rank<r>.npz (the C++ solver
writes .bin files of its own format): a restart needs the same scene (by its
fingerprint: the file's text and the --set overrides) and the same number
of ranks. A checkpoint replaces the previous one only once it is complete."""
import os

import numpy as np
from mpi4py import MPI

from ..scene.scene import SceneError, agree_on_error

FORMAT = "biotcontact checkpoint 1 (prototype)"


class Checkpoint:
    def __init__(self, steps=0, time=0.0, arrays=None, numbers=None, output=""):
        self.steps, self.time = steps, time
        self.arrays = arrays or {}    # this rank's, ghosts included
        self.numbers = numbers or {}  # counters and scales
        self.output = output          # Output.position()


def _path(directory, rank):
    return os.path.join(directory, "checkpoint", f"rank{rank}.npz")


def write_checkpoint(comm, directory, fingerprint, c):
    if comm.rank == 0:
        os.makedirs(os.path.join(directory, "checkpoint"), exist_ok=True)
    comm.Barrier()
    path = _path(directory, comm.rank)
    with open(path + ".new", "wb") as f:
        np.savez(f, format=FORMAT, fingerprint=fingerprint, ranks=comm.size, steps=c.steps, time=c.time,
                 output=c.output, number_names=list(c.numbers), number_values=list(c.numbers.values()),
                 **{"array_" + name: values for name, values in c.arrays.items()})
    comm.Barrier()  # every rank's new file is complete before any replaces the old one
    os.replace(path + ".new", path)
    comm.Barrier()


def read_checkpoint(comm, directory, fingerprint):
    path, error, c = _path(directory, comm.rank), "", Checkpoint()
    try:
        if not os.path.exists(path):
            raise SceneError(f"--restart {directory}: no checkpoint there ({path}; runs write one with "
                             "output.checkpoint_every)")
        with np.load(path) as data:
            if str(data["format"]) != FORMAT:
                raise SceneError(f"--restart {directory}: {path} is no biotcontact checkpoint")
            if str(data["fingerprint"]) != fingerprint:
                raise SceneError(f"--restart {directory}: the checkpoint was written for another scene or other "
                                 "--set values")
            if int(data["ranks"]) != comm.size:
                raise SceneError(f"--restart {directory}: the checkpoint was written by {int(data['ranks'])} "
                                 "ranks; restart with as many")
            c.steps, c.time, c.output = int(data["steps"]), float(data["time"]), str(data["output"])
            c.numbers = dict(zip((str(n) for n in data["number_names"]), (float(v) for v in data["number_values"])))
            c.arrays = {k[len("array_"):]: data[k] for k in data.files if k.startswith("array_")}
    except SceneError as e:
        error = str(e)
    except (OSError, KeyError, ValueError):
        error = f"--restart {directory}: the checkpoint {path} is damaged"
    agree_on_error(error, comm)
    if comm.allreduce(c.steps, op=MPI.MAX) != comm.allreduce(c.steps, op=MPI.MIN):
        raise SceneError(f"--restart {directory}: the ranks' checkpoint files are of different steps")
    return c
