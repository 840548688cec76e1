"""A problem each rank solves alone, the same problem on every rank (the
condensed contact VI, contact/contact.py): the same outcome in exact
arithmetic, not always in floating point (threads, another node's kernels).
Rank 0's outcome becomes every rank's, so that what the ranks decide from
it, and their next collective calls, are the same (cpp/solvers/
shared_outcome.h)."""
import dataclasses


@dataclasses.dataclass
class SolveOutcome:
    """How a solve ended on a rank: its converged reason (PETSc's: negative
    when it diverged) and, when it failed, the failure's text."""
    reason: int = 0
    failure: str = ""  # empty unless the solve failed


def shared_outcome(mine, y, comm):
    """Rank 0's outcome, and rank 0's values of `y` (a sequential vector of
    the same size on every rank), on every rank of `comm` (an mpi4py
    communicator; collective)."""
    if comm.size == 1:
        return mine
    shared = comm.bcast(mine, root=0)
    values = y.getArray(readonly=True).copy()
    comm.Bcast(values, root=0)
    y.setArray(values)
    return shared
