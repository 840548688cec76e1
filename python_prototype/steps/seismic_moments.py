"""The faults' seismic moments step by step (cpp/steps/seismic_moments.h;
docs/user-guide.md, "Faults": M0 = sum over a fault's pairs of G |slip
increment| times their lumped measure): what the mechanics and the
monolithic step record at each accepted step, keep in checkpoints and give
the summary."""
import dataclasses

import numpy as np


@dataclasses.dataclass
class SeismicMoments:
    """The faults' seismic moments step by step (FaultSummary.moment): per
    accepted step its time, then the moment of each of `names`."""
    names: list = dataclasses.field(default_factory=list)
    steps: list = dataclasses.field(default_factory=list)


def moments_of(contact_set):
    """An empty record of the faults of `contact_set` (its boundaries that
    are faults)."""
    return SeismicMoments([name for name, fault in zip(contact_set.boundaries, contact_set.faults) if fault])


def record_moments(moments, t, state):
    """Adds the step accepted at t, each fault's moment of the ContactState
    `state` (its contact state at t)."""
    moments.steps += [t] + [f.moment for f in state.faults]


def keep_moments(moments, arrays):
    """Puts the record into a checkpoint's arrays, "seismic_moments"
    (nothing while it is empty)."""
    if moments.steps:
        arrays["seismic_moments"] = np.array(moments.steps)


def restore_moments(moments, arrays):
    """Takes the record back from a checkpoint's arrays."""
    if "seismic_moments" in arrays:
        moments.steps = [float(v) for v in arrays["seismic_moments"]]
