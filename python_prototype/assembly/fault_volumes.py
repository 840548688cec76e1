"""The fluid volumes of the conduit faults (cpp/assembly/fault_volumes.h):
each fault's volumes since the run's start and of each step, their balance
(injected + exchanged + intersections = stored + outflow, docs/theory.md
"Converged means balanced") and the volume rates through the faults'
intersections. ConduitFaults counts them: fault_flow_volumes.py."""
import dataclasses

import numpy as np


@dataclasses.dataclass
class IntersectionRate:
    """Where a set of conduit faults meets (their junctions of
    fault_network: a point in 2D, a line's edges in 3D): the faults, in the
    scene's order, the number of junctions and the volume rate through them
    at the last accepted step's end (m^3/s; m^2/s per metre of thickness in
    2D), at each junction the sum of its members' flows into it (which the
    flows out of it equal)."""
    faults: list
    junctions: int = 0
    rate: float = 0.0


@dataclasses.dataclass
class FaultVolumes:
    """A conduit fault's fluid volumes since the run's start (m^3; m^2 per
    metre of thickness in 2D): injected by its wells, stored (the volume its
    opening made and its fluid's compression), exchanged (from the rock
    through its faces), out of its ends on pressure boundaries and in from the
    other conduit faults where they meet (intersections). Step by step,
    injected + exchanged + intersections = stored + outflow."""
    injected: float = 0.0
    stored: float = 0.0
    exchanged: float = 0.0
    outflow: float = 0.0
    intersections: float = 0.0


@dataclasses.dataclass
class StepVolumes:
    """A fault's volumes of one step (net, FaultVolumes); the sum of the
    magnitudes of every face's, well's, cell's and end's term in them
    (gross); the fluid it holds at the step's end (held, sum of
    w_h |k|); and dt sum |c_i| over its faces (faces: times the rock's
    largest flux DOF, the exchange the rock's round-off can make)."""
    net: FaultVolumes = dataclasses.field(default_factory=FaultVolumes)
    gross: float = 0.0
    held: float = 0.0
    faces: float = 0.0


# How far an accepted step may leave a fault's volumes unbalanced
# (volume_imbalance). Converged runs measure up to 6e-6 (the 3D closure box
# with its flow solved by the Krylov method, whose tolerance is relative to
# a load inflated by the held ends); the wrong answers this stops, 1e-4 and
# more (docs/theory.md, "Converged means balanced").
VOLUME_BALANCE_TOLERANCE = 1e-5


def volume_imbalance(step, total, rock_flux):
    """The imbalance |injected + exchanged - stored - outflow| of StepVolumes
    `step` relative to the largest of `total` (the fault's volumes since
    the start, the step included), the step's gross volume, 1e-6 of the
    fluid the fault holds and 1e-8 of step.faces times `rock_flux`, the
    rock's largest flux DOF (at the tolerance, 1e-11 and 1e-13 of them:
    round-off): 0 when nothing moved."""
    scale = max(abs(total.injected), abs(total.stored), abs(total.exchanged), abs(total.outflow),
                abs(total.intersections), step.gross,
                1e-6 * step.held, 1e-8 * step.faces * rock_flux)
    v = step.net
    imbalance = abs(v.injected + v.exchanged + v.intersections - v.stored - v.outflow)
    if imbalance == 0:
        return 0.0
    with np.errstate(divide="ignore", invalid="ignore"):
        return float(np.float64(imbalance) / np.float64(scale))  # NaN or inf when a volume is
