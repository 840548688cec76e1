"""Wells: point (2D) or vertical line (3D) sources and sinks in the cells
that contain them, added to the flow's right-hand side
(cpp/assembly/wells.cpp)."""
import numpy as np

from ..domain.wells import locate_well


class WellSource:
    """One well in the mass balance: its rate R(t) spread over its cells, the
    source R share_K / |K| on cell K, whose integral against the cell's P0
    test function is R share_K in the cell's pressure row."""

    def __init__(self, rate, rows, shares):
        self.rate, self.rows, self.shares = rate, rows, shares


def well_sources(scene, domain, Q, Q_to_vector):
    """The wells of a scene into the rock, in a vector whose pressure part
    (the P0 space Q) sits at `Q_to_vector` (a well into a conduit fault is
    fault_flow.py's)."""
    wells = []
    for name, w in sorted(scene.wells.items()):  # the order of the C++ std::map
        if w.fault:
            continue
        cells, shares = locate_well(domain, w, f"well.{name}.position")
        dofs = Q.dofmap.list.array.reshape(-1, 1)[cells, 0]
        wells.append(WellSource(w.rate, np.asarray(Q_to_vector)[dofs], shares))
    return wells


def add_wells(wells, t, b):
    """b -= R(t) share in each well cell's row: forms/biot.py writes the mass
    balance times -1, its source term as -(Q, th)."""
    for w in wells:
        b[w.rows] -= float(w.rate(0, 0, 0, t)) * w.shares


def depends_on_time(wells):
    """Whether any well's rate changes in time."""
    return any(w.rate.depends_on_time for w in wells)
