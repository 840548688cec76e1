"""SIGINT and SIGTERM end a run cleanly (cpp/output/interruption.h): the handler
only records the signal; the time loop checks it after each completed (and
written) step, then stops, closes its files and writes summary.json with
"status": "interrupted"; the process exits with 128 + the signal number.
A second signal stops it at once, as SIGKILL would (every output time is
flushed as it is written)."""
import os
import signal

from mpi4py import MPI

_received = 0


def _record(number, frame):
    global _received
    if _received:  # the second signal: its default action (Python runs this between PETSc calls)
        signal.signal(number, signal.SIG_DFL)
        os.kill(os.getpid(), number)
        return
    _received = number


def install_interruption_handlers():
    signal.signal(signal.SIGINT, _record)
    signal.signal(signal.SIGTERM, _record)


def interruption_signal(comm):
    """The signal received by any rank so far, 0 if none (collective): the
    ranks agree so that all stop after the same step."""
    return comm.allreduce(_received, op=MPI.MAX)
