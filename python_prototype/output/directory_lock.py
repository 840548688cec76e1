"""One run per output directory (cpp/output/directory_lock.h): a run holds an
operating-system lock (flock, exclusive, not waiting) on DIR/.lock while it
writes there; a second run into the directory, of either track, stops with
one line naming the holder before it creates or truncates anything. The
kernel drops the lock when the process ends, however it ends."""
import fcntl
import os
import socket
import time

from ..scene.scene import agree_on_error

FILE_NAME = ".lock"


def _holder(fd):
    text = os.pread(fd, 255, 0).decode(errors="replace").rstrip("\n ")
    return text or "an unknown process"


def _this_process():
    started = time.strftime("%Y-%m-%d %H:%M:%S", time.localtime())
    return f"process {os.getpid()} on {socket.gethostname()}, started {started}\n"


class DirectoryLock:
    """Creates the directory if needed and takes its lock on rank 0; every
    rank raises the one-line error if another process holds it."""

    def __init__(self, comm, directory):
        self.fd = None
        error = ""
        if comm.rank == 0:
            error = self._take(directory)
        agree_on_error(error, comm)

    def _take(self, directory):
        try:
            os.makedirs(directory, exist_ok=True)
        except OSError as e:
            return f"--out {directory}: cannot create the output directory: {e.strerror}"
        try:
            self.fd = os.open(os.path.join(directory, FILE_NAME), os.O_RDWR | os.O_CREAT | os.O_CLOEXEC, 0o644)
        except OSError as e:
            return f"--out {directory}: cannot create the lock file {FILE_NAME}: {e.strerror}"
        try:
            fcntl.flock(self.fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError:
            holder = _holder(self.fd)
            os.close(self.fd)
            self.fd = None
            return (f"--out {directory}: the directory is in use by another run ({holder}); one run per "
                    "output directory: choose another --out or wait for it to end")
        try:
            os.ftruncate(self.fd, 0)
            os.pwrite(self.fd, _this_process().encode(), 0)
        except OSError as e:
            return f"--out {directory}: cannot write the lock file {FILE_NAME}: {e.strerror}"
        return ""

    def release(self):
        if self.fd is not None:
            os.close(self.fd)
            self.fd = None
