"""The volume bookkeeping of the conduit faults (ConduitFaults,
fault_flow.py; cpp/assembly/fault_flow_volumes.cpp): each step's volumes of
each fault, their balance, their sums since the start and the rates
through the intersections (fault_volumes.py); and what a checkpoint keeps
of the faults between steps."""
import collections

import numpy as np

from .fault_volumes import VOLUME_BALANCE_TOLERANCE, FaultVolumes, IntersectionRate, StepVolumes, volume_imbalance


class ConduitVolumes:
    """The volume bookkeeping of ConduitFaults (assembly/fault_flow.py), its
    base class: the methods below read the faults' cells, faces, wells,
    ends and junctions that ConduitFaults holds."""

    def step_volumes(self, w, p, p_old, fine):
        """Each fault's StepVolumes of FineStep `fine` (every rank): `w` the
        flow unknowns (this rank's), `p` and `p_old` the fault's pressure at
        its end and start (this rank's entries; collective)."""
        # BDF2 balances its derivative, c0 (y - y*)/dt_n, against the rates
        # over the step dt_n = c0 fine.dt: stored = c0 (y - y*) (time_scheme.py).
        t, c0 = fine.t, fine.c[0]
        dt = c0 * fine.dt
        p_star = self._pressure_history(fine, self.rows.everywhere(p_old))
        p = self.rows.everywhere(p)
        # Per fault: injected, stored, exchanged, outflow of the step, gross,
        # held and faces; the faces on the ranks that own them, the rest by
        # each cell's owner (a junction's link by its first member's). The
        # intersections in the 8th column.
        step = np.zeros((len(self.faults), 8))

        def add(i, column, v):
            step[i, column] += np.sum(v)
            step[i, 4] += np.sum(np.abs(v))
        index = {id(conduit): i for i, conduit in enumerate(self.faults)}
        for dof, conduit, _, c in self.faces:
            add(index[id(conduit)], 2, dt * c * w[dof - self.start])
            step[index[id(conduit)], 6] += dt * abs(c)
        for row, share, rate, i in self.wells:
            if self.rows.owns(row):
                add(i, 0, dt * share * float(rate(0, 0, 0, t)))
        for i, conduit in enumerate(self.faults):
            cells, o, n = conduit.cells, conduit.offset, len(conduit.cells.measures)
            mine = self.rows.owner[o:o + n] == self.rows.rank
            add(i, 1, (c0 * cells.measures * (conduit.aperture - self._aperture_history(conduit, fine)) / fine.q
                       + c0 * self.flow.c_f * conduit.aperture * cells.measures * (p[o:o + n] - p_star[o:o + n]))[mine])
            step[i, 5] += np.sum((cells.measures * conduit.aperture)[mine])
            held, T_e = self._held_ends(conduit)
            k = o + cells.ends.cells[held, 0]
            ends = dt * T_e * (p[k] - self._end_pressures(conduit, held, t))
            add(i, 3, ends[self.rows.owner[k] == self.rows.rank])
        for (a, b), (fa, fb), T_ab, _, _ in self._junction_links():
            if fa != fb and self.rows.owns(a):  # from the first member's fault into the second's
                V = dt * T_ab * (p[a] - p[b])
                add(fa, 7, -V)
                add(fb, 7, V)
        return [StepVolumes(FaultVolumes(*(float(x) for x in row[[0, 1, 2, 3, 7]])), *(float(x) for x in row[4:7]))
                for row in self.comm.allreduce(step)]

    def unbalanced(self, step, rock_flux):
        """The first fault that `step` (step_volumes) leaves unbalanced by
        more than VOLUME_BALANCE_TOLERANCE (volume_imbalance, `rock_flux`
        the rock's largest flux DOF): one line naming it and the imbalance;
        empty when every fault balances."""
        for conduit, volumes in zip(self.faults, step):
            v, s = conduit.volumes, volumes.net
            total = FaultVolumes(v.injected + s.injected, v.stored + s.stored, v.exchanged + s.exchanged,
                                 v.outflow + s.outflow, v.intersections + s.intersections)
            imbalance = volume_imbalance(volumes, total, rock_flux)
            if not imbalance <= VOLUME_BALANCE_TOLERANCE:  # NaN too
                network = bool(self.junctions)
                return (f"fault.{conduit.name}: its volumes do not balance: injected + exchanged"
                        f"{' + intersections' if network else ''} - stored - outflow = "
                        f"{s.injected + s.exchanged + s.intersections - s.stored - s.outflow:g} in the step (injected "
                        f"{s.injected:g}, exchanged {s.exchanged:g}"
                        f"{f', intersections {s.intersections:g}' if network else ''}, stored {s.stored:g}, outflow "
                        f"{s.outflow:g}), {imbalance:g} of the volumes, more than {VOLUME_BALANCE_TOLERANCE:g}")
        return ""

    def add_volumes(self, step, fine, p_start):
        """Adds the accepted fine step's volumes (step_volumes) to each
        fault's. After a window's last fine step its apertures become the
        next window's start, and the start's apertures and pressure
        `p_start` (this rank's entries) the values one step before, which
        BDF2 reads (collective)."""
        if fine.m == fine.q:
            self.pressure_before = self.rows.everywhere(p_start)
        for conduit, volumes in zip(self.faults, step):
            v, s = conduit.volumes, volumes.net
            v.injected, v.stored, v.exchanged, v.outflow = (v.injected + s.injected, v.stored + s.stored,
                                                             v.exchanged + s.exchanged, v.outflow + s.outflow)
            v.intersections += s.intersections
            if fine.m == fine.q:
                conduit.aperture_before, conduit.aperture_start = conduit.aperture_start, conduit.aperture.copy()

    def set_intersection_rates(self, p):
        """Sets each intersection's rate from `p`, the faults' pressure at an
        accepted step's end (this rank's entries; collective): each member's
        net flow into the junction, sum_b T_ab (p_a - p_b) over its links
        there; the positive ones summed are what passes through (every rank
        alike, from every cell's p)."""
        if not self.junctions:  # the same on every rank
            return
        p = self.rows.everywhere(p)
        into = collections.defaultdict(float)  # (junction, row)
        for (a, b), _, T_ab, _, j in self._junction_links():
            q = T_ab * (p[a] - p[b])
            into[j, a] += q
            into[j, b] -= q
        through = np.zeros(len(self.junctions))
        for (j, _), q in into.items():
            through[j] += max(q, 0.0)
        self._through = through

    def intersection_rates(self):
        """The rates by set of faults that meet, in the order of their names
        (the same on every rank)."""
        by_faults = {}
        for j, junction in enumerate(self.junctions):
            names = tuple(self.faults[f].name for f in sorted(set(junction.faults)))
            r = by_faults.setdefault(names, IntersectionRate(list(names)))
            r.junctions += 1
            r.rate += float(self._through[j])
        return [by_faults[names] for names in sorted(by_faults)]

    def volumes(self):
        """Each conduit fault's name and volumes (the same on every rank)."""
        return [(conduit.name, conduit.volumes) for conduit in self.faults]

    def volume_values(self):
        """The volumes as 5 numbers per fault (a checkpoint's)."""
        return np.array([[v.injected, v.stored, v.exchanged, v.outflow, v.intersections]
                         for _, v in self.volumes()]).ravel()

    def set_volume_values(self, values):
        n = len(values) // len(self.faults) if self.faults else 5  # 4 in the checkpoints before the intersections
        for i, conduit in enumerate(self.faults):
            conduit.volumes = FaultVolumes(*(float(x) for x in values[n * i:n * i + n]))

    def start_apertures(self):
        """The hydraulic apertures at the start of the step, every cell (the
        same on every rank): the last accepted step's (add_volumes), which a
        checkpoint keeps and restores (set_start_apertures)."""
        return np.concatenate([conduit.aperture_start for conduit in self.faults])

    def set_start_apertures(self, w_h):
        for conduit in self.faults:
            conduit.aperture_start = np.array(w_h[conduit.offset:conduit.offset + len(conduit.aperture_start)])
        self.started = True

    def arrays(self, p):
        """What a checkpoint keeps of the faults: their pressure p (this
        rank's entries), "fault_pressure" (every cell on every rank), the volumes,
        "fault_volumes", the start apertures, "fault_apertures", and the
        pressure and apertures one step before (BDF2), "fault_pressure_before"
        and "fault_apertures_before" (collective)."""
        pressure = self.rows.everywhere(p)
        return {"fault_pressure": pressure,
                "fault_volumes": self.volume_values(), "fault_apertures": self.start_apertures(),
                "fault_pressure_before": pressure if self.pressure_before is None else self.pressure_before,
                "fault_apertures_before": np.concatenate([conduit.aperture_before for conduit in self.faults])}

    def restore_arrays(self, arrays, p):
        """The checkpoint's arrays back into p (in place) and the faults.
        Checkpoints before BDF2's conduits have no values of the step
        before: they are then the start's (only backward Euler reads them
        there)."""
        pressure = np.asarray(arrays["fault_pressure"], dtype=float)  # every cell
        p[:] = self.rows.entries(pressure)
        self.set_volume_values(arrays["fault_volumes"])
        if "fault_apertures" in arrays:
            self.set_start_apertures(arrays["fault_apertures"])
        self.pressure_before = np.array(arrays.get("fault_pressure_before", pressure), dtype=float)
        before = arrays.get("fault_apertures_before")
        for conduit in self.faults:
            n = len(conduit.aperture_start)
            conduit.aperture_before = (conduit.aperture_start.copy() if before is None
                                       else np.array(before[conduit.offset:conduit.offset + n]))
