"""A file of the run that cannot be written (cpp/output/write_failure.h): a
full disk, a quota, a lost mount. The run stops at the write that failed,
with one line naming the file and the system's reason, and keeps
everything written before (exit status RUN_OUTPUT_FAILED)."""
import errno
import os
import re


class OutputError(RuntimeError):
    """A file of the run could not be written; the message names the file
    and the reason."""


def write_failure_reason(directory, error=None):
    """Why the write into `directory` failed, as the system says it (the
    OSError's words, or HDF5's record of them), with the space left on the
    device; one line."""
    # HDF5 (h5py) records the system's words as "error message = '...'".
    hdf5 = re.search(r"error message = '([^']*)'", str(error)) if error is not None else None
    reason = hdf5.group(1) if hdf5 else error.strerror if isinstance(error, OSError) and error.strerror else ""
    reason = reason.split("\n")[0]
    try:
        disk = os.statvfs(directory)
    except OSError:
        disk = None
    if disk is not None:
        if not reason and disk.f_bavail == 0:
            reason = os.strerror(errno.ENOSPC)
        left = f"{disk.f_bavail * disk.f_frsize / 1e6:.3g} MB left on the device"
        reason += ("; " if reason else "") + left
    return reason or "the system gave no reason"


def agree_on_output_error(failed, comm):
    """Raises OutputError with the lowest failing rank's message on every
    rank when `failed` is not empty on any (collective)."""
    # Imported here: readers of the output (time_series.Fields in the tests)
    # import this module and must not start MPI in their process, whose
    # mpirun children would then fail.
    from mpi4py import MPI
    owner = comm.allreduce(comm.rank if failed else comm.size, op=MPI.MIN)
    if owner < comm.size:
        raise OutputError(comm.bcast(failed, root=owner))


# Datasets whose file the disk refused, kept open until the process ends
# (os._exit: __main__.py): h5py closes a dropped handle and reports a close
# the disk refused on stderr only, after the fact.
_REFUSED = []


def write_dataset(h5, path, data):
    """Writes `data` as the dataset `path` of the h5py file `h5`, replacing
    it, and flushes the file while the dataset's handle is open, so that a
    full disk raises here (RuntimeError or OSError)."""
    if path in h5:  # a resumed run writes again what its first run wrote after the checkpoint
        del h5[path]
    dataset = h5.create_dataset(path, data=data)
    try:
        h5.flush()
    except (OSError, RuntimeError):
        _REFUSED.append(dataset)
        raise
