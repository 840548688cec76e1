"""What one solve of a step measured, a row of iterations.csv for the
schemes with one solve per step (coupling/single_solve.py): the monolithic
system (one row per iteration on its conduit faults' apertures) and a single
physics (cpp/steps/solve_record.h)."""
import math
from dataclasses import dataclass

import numpy as np
from mpi4py import MPI


@dataclass
class SolveRecord:
    """What one solve measured: the l2 norms of p, u and the conduit faults'
    p_f after it and of their change since the solve before (the step's start
    for the first; NaN where the step has no such field), and its contact
    solve's Newton steps and active nodes. The scheme makes the changes
    relative, as the split's stopping test does."""
    dp: float = math.nan
    p: float = math.nan
    du: float = math.nan
    u: float = math.nan
    fault_dp: float = math.nan
    fault_p: float = math.nan
    active_nodes: int = 0
    newton_steps: int = 0


@dataclass
class FieldValues:
    """A field a solve moves: its values on this rank and how many of the
    first are held by this rank alone (the rest are ghosts or copies), so
    that each value counts once over the ranks; None: the step has none."""
    values: np.ndarray = None
    owned: int = 0


@dataclass
class SolveFields:
    """The fields of a step that its solves move: p, u and p_f, and the
    communicator of their ranks."""
    p: FieldValues
    u: FieldValues
    fault_p: FieldValues
    comm: MPI.Comm


class SolveMeter:
    """Measures a step's solves: remembers the fields before a solve and
    records its change."""

    def __init__(self):
        self._before = [None, None, None]
        self._newton_steps = 0

    def start(self, fields, newton_steps):
        """The fields (and the contact Newton steps so far) before a solve."""
        self._before = [None if f.values is None else f.values[:f.owned].copy()
                        for f in (fields.p, fields.u, fields.fault_p)]
        self._newton_steps = newton_steps

    def record(self, fields, newton_steps, active_nodes):
        """The record of the solve since start() (collective): the fields and
        Newton steps now, the active nodes after it."""
        squares = np.zeros(6)
        every = (fields.p, fields.u, fields.fault_p)
        for i, f in enumerate(every):
            if f.values is not None:
                now = f.values[:f.owned]
                squares[2 * i:2 * i + 2] = [np.dot(now - self._before[i], now - self._before[i]), np.dot(now, now)]
        squares = fields.comm.allreduce(squares, op=MPI.SUM)
        norms = [math.sqrt(squares[j]) if every[j // 2].values is not None else math.nan for j in range(6)]
        return SolveRecord(*norms, active_nodes, newton_steps - self._newton_steps)

    def failed(self, newton_steps, active_nodes):
        """The record of a solve since start() that failed: its Newton steps,
        no change of the fields (NaN: it left them as they were)."""
        return SolveRecord(active_nodes=active_nodes, newton_steps=newton_steps - self._newton_steps)
