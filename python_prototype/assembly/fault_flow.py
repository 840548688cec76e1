"""The flow inside "conduit" faults (cpp/assembly/fault_flow.h,
docs/theory.md "Flow in a fault"): the fault's pressure p_f, one unknown per
fault cell (domain/fault_cells.py), appended to the flow system after the
rock's unknowns (fault_rows.py). Per cell k, the mass balance times -1
(as forms/biot.py writes the rock's),

    sum_i c_i z_i - ((S_k + L_k)/dt) p_k - sum_l T_kl (p_k - p_l) - sum_ends T_e (p_k - p_D)
        = -(S_k/dt) p_k^old - (L_k/dt) p_k^i + |k| (w_k - w_k^old)/dt,

w_k the hydraulic aperture w_h (set_openings), S_k = w_h c_f |k|, T_kl the
cubic law's two-point transmissibility, c_i the faces' facet fluxes, L_k =
L_f |k| the fixed-stress term (_set_compliance). The operator stays symmetric."""
import dataclasses
import math

import numpy as np
from petsc4py import PETSc

from ..domain.fault_cells import fault_network, well_cells
from ..scene.input import FaultFlow
from .boundary_conditions import fault_face_rows
from .fault_compliance import closure_aperture, softest_modulus
from .fault_flow_compliance import ConduitCompliance
from .fault_flow_jacobian import ConduitJacobian
from .fault_flow_pins import CellPins, ConduitPins
from .fault_flow_volumes import ConduitVolumes
from .fault_rows import fault_rows
from .fault_volumes import FaultVolumes


@dataclasses.dataclass
class FineStep:
    """Fine step m (1..q) of a window of q flow steps, ending at t, of length
    dt: with the mechanics once per window, each fine step takes 1/q of the
    window's change of aperture, as the rock's flow takes (alpha/q) div(u^n -
    u_K) (paper eq. 4.17). A step of the single-rate split is m = q = 1.
    `c` holds the time derivative's (c0, c1, c2) (time/time_scheme.py): dt is
    then the effective step dt_n/c0, and the history value y* = (c1 y_n -
    c2 y_{n-1})/c0 of the fault's pressure and aperture stands where
    backward Euler reads y_n (BDF2; single rate only)."""
    t: float = 0.0
    dt: float = 0.0
    m: int = 1
    q: int = 1
    c: tuple = (1.0, 1.0, 0.0)  # backward Euler by default


def history_value(step, y, y_before):
    """The history value y* = (c1 y - c2 y_before)/c0 of `step` (FineStep.c,
    as time_scheme.py's), y itself for backward Euler."""
    c0, c1, c2 = step.c
    y = np.asarray(y, dtype=float)
    return y.copy() if c2 == 0 else (c1 * y - c2 * np.asarray(y_before, dtype=float)) / c0


@dataclasses.dataclass
class _Conduit:
    """One conduit fault's cells and what the flow needs of it."""
    name: str
    offset: int            # its first cell among the appended unknowns
    cells: object          # FaultCells
    aperture: np.ndarray   # w_h per cell (m)
    aperture_start: np.ndarray  # w_h at the start of the step
    aperture_before: np.ndarray  # w_h at the start of the step before (BDF2)
    residual: float        # w_r
    closure: object        # ClosureSpec or None
    modulus: float         # E' of the softest rock, 0 without mechanics
    open: np.ndarray       # per cell: w > e at the last mechanics iterate
    open_before: np.ndarray  # ... at the one before
    compliance: np.ndarray  # per cell: L_f (m/Pa) of its patch or closure, 0 where no L
    traction: np.ndarray   # per cell: s_n at the last mechanics iterate (with a closure)
    normal_resistance: float  # mu_f / (2 k_n): times w_h, the face's resistance (0 for k_n = inf)
    permeability: float    # k_f (m^2): the transmissivity k_f w_h; 0: the cubic law's w_h^3 / 12
    volumes: FaultVolumes = dataclasses.field(default_factory=FaultVolumes)  # since the run's start
    conducting: np.ndarray = None  # the aperture of the cubic law: w_h relaxed (Aitken)
    lag: np.ndarray = None         # w_h - conducting at the last set_openings
    links: object = None           # FaultEdges: the cells' links but those at junctions (fault_network)
    pinning: object = None         # CellPins: its cells' flips and pins in the step (fault_flow_pins.py)


# Below this fraction of the residual aperture a cell's mean opening is the
# round-off of u+ - u- at closed pairs (1e-17 m at 0.1 m of displacement),
# not an opening: amplified by 1/(c_f w_r) it would move p_f, and a closed
# cell taken for open would take the fixed-stress term L_f, under which it
# converges at the rate L_f/(L_f + S), nearly 1.
OPEN_FRACTION = 1e-6

# The conducting apertures of the cubic law follow w_h whole while the lag
# between them shrinks by this factor per iteration (the monolithic step's
# aperture iterations, the split's coupling iterations); once it does not,
# the split relaxes them by Aitken's factor and the monolithic step takes
# Newton's term of the transmissibilities (theory.md, "Flow in a fault").
RELAXED_ABOVE = 0.9
# In the split, whose lag shrinks at the coupling's rate after a transient,
# Aitken's relaxation starts once the lag grew at this many coupling
# iterations in a row (the lagged cubic law's 2-cycle).
STALLED_ITERATIONS = 3
# A lag below the openings' round-off that has not halved over this many of
# the split's iterations is noise: the floor of the relaxation holds the
# apertures from then to the step's end (Aitken's factor from noise cycled
# with period 4).
LAG_WINDOW = 4


def transmissibilities(t, edges):
    """The two-point transmissibility |e| / (sum_k d_k / t_k) of each of the
    FaultEdges `edges` (t: per cell, the cubic law's w_h^3 / (12 mu_f)): |e|
    the measure of the edge between the cells, d_k its distance to each
    centroid."""
    return edges.measures / np.sum(edges.distances / t[edges.cells], axis=1)


class ConduitFaults(ConduitVolumes, ConduitJacobian, ConduitCompliance, ConduitPins):
    """The conduit faults of a scene: their cells, numbered fault by fault
    in the scene's order, appended after the flow system's unknowns, each on
    the rank that owns its first node (fault_rows.py); the faces' flux DOFs
    on the ranks that own them. Every rank keeps every cell's geometry and
    apertures (a fault holds few facets); "this rank's entries" of the
    pressure are its owned cells', in the cells' order."""

    def __init__(self, scene, domain, Z, flux):
        """`flux(marker)`: the facet flux of the flux basis functions
        (boundary_conditions.facet_flux); Z: the flux subspace."""
        self.comm, self.flow = domain.mesh.comm, scene.flow
        self.faults, self.faces, self.wells, count = [], [], [], 0
        self.pressure_boundaries = {name: b.pressure for name, b in scene.boundaries.items() if b.flow == "pressure"}
        for name, f in sorted(scene.faults.items()):  # the order of the C++ std::map
            if f.flow != FaultFlow.conduit:
                continue
            cells = domain.faults[name].cells
            resistance = 0.0 if np.isinf(f.normal_permeability) else self.flow.mu_f / (2 * f.normal_permeability)
            w_r = np.full(len(cells.measures), f.residual_aperture)
            n = len(cells.measures)
            conduit = _Conduit(name, count, cells, w_r, w_r.copy(), w_r.copy(), f.residual_aperture, f.closure,
                               softest_modulus(scene) if scene.mechanics else 0.0, np.zeros(n, dtype=bool),
                               np.zeros(n, dtype=bool), np.zeros(n), np.zeros(n), resistance, f.permeability)
            index = {tuple(key): k for k, key in enumerate(cells.keys.tolist())}
            for _, key, dof, c in fault_face_rows(domain, Z, name, flux(domain.fault_faces(name))):
                self.faces.append((dof, conduit, index[key], c))
            self.faults.append(conduit)
            self._locate_wells(scene, name, cells, count)
            count += len(cells.measures)
        network = fault_network([conduit.cells for conduit in self.faults])
        for conduit, links in zip(self.faults, network.links):
            conduit.links = links
        self.junctions = network.junctions  # where the conduits meet
        self._through = np.zeros(len(self.junctions))  # per junction: its rate (set_intersection_rates)
        self.size = count
        self.start = Z.dofmap.index_map.local_range[0]  # the global index of this rank's first flow unknown
        self.rows = fault_rows(scene, domain)
        self.owned = self.rows.owned
        self.dim = domain.mesh.topology.dim
        self.started = False  # whether the start apertures are known
        self.pressure_before = None  # p_f at the start of the step before (every cell; BDF2)
        self.stabilised = True  # whether the cells take L (_set_compliance)
        self.implicit = False  # whether open cells' openings are unknowns (with_implicit_openings)
        self.aperture_change = 0.0
        self.relaxed = 1.0  # Aitken's factor before Newton's term (_relax_conducting, drop_newton)
        self.begin_step()  # the relaxation's state

    def _locate_wells(self, scene, fault, cells, offset):
        """The wells into the fault `fault`: (row, share, rate) per cell each
        meets (mesh_checks.py has checked that each meets one)."""
        for name, w in sorted(scene.wells.items()):  # the order of the C++ std::map
            if w.fault != fault:
                continue
            hit, shares = well_cells(cells, w)
            self.wells += [(offset + int(k), float(share), w.rate, len(self.faults) - 1)
                           for k, share in zip(hit, shares)]

    def __bool__(self):
        return self.size > 0

    def initial_pressure(self, p0):
        """p_f at the start: the expression p0 at the cells' centroids (this
        rank's entries)."""
        if not self.size:
            return np.zeros(0)
        x = np.concatenate([conduit.cells.centroids for conduit in self.faults])
        return self.rows.entries(np.asarray(p0.at(x.T, 0.0), dtype=float) * np.ones(len(x)))

    def exchange(self, flow_rows):
        """B: the fault's rows against the flow unknowns, c_i at each face
        DOF (`flow_rows`: the flow system's local size; collective). The
        faces' RT0 fluxes z_i enter with their facet flux c_i = <w_i.n, 1>,
        and the rows of z_i get +c_i p_k: the rock's pressure at a face is
        p_f (the boundary-pressure term with p_D = p_f), plus mu_f
        (w_h/2)/k_n z.n across a finite normal permeability k_n
        (face_resistance)."""
        B = PETSc.Mat().createAIJ(((self.owned, None), (flow_rows, None)), comm=self.comm)
        B.setPreallocationNNZ((2, 2))
        B.setOption(PETSc.Mat.Option.NEW_NONZERO_ALLOCATION_ERR, False)
        for dof, conduit, k, c in self.faces:
            B.setValue(self.rows.row[conduit.offset + k], dof, c)
        B.assemble()
        return B

    def face_resistance(self):
        """The rows of the face DOFs across a finite normal permeability:
        (dof, mu_f (w_h/2)/k_n <w_i.n, w_i.n>) with w_i.n = c_i/|face|."""
        return [(dof, conduit.normal_resistance * conduit.aperture[k] * c * c / conduit.cells.measures[k])
                for dof, conduit, k, c in self.faces if conduit.normal_resistance > 0]

    def _storage(self, conduit, dt):
        """S_k / dt = w_h c_f |k| / dt per cell."""
        return conduit.aperture * self.flow.c_f * conduit.cells.measures / dt

    def _conductance(self, conduit):
        """t per cell: k_f w / mu_f with the fault's own permeability, else the
        cubic law's w^3 / (12 mu_f); w the conducting aperture (w_h itself
        before the first mechanics iterate or without mechanics)."""
        w = conduit.aperture if conduit.conducting is None else conduit.conducting
        if conduit.permeability > 0:
            return conduit.permeability * w / self.flow.mu_f
        return w ** 3 / (12 * self.flow.mu_f)

    def _junction_links(self):
        """Every junction's links, the intersection's pressure eliminated:
        ((row a, row b), (conduit a, conduit b), T_ab, the junction's point,
        its index in self.junctions).
        p_j eliminated from sum_i h_i (p_i - p_j) = 0 leaves between each two
        members h_a h_b / sum_i h_i (a star-delta transform: exact). Member i
        reaches the intersection through half its cell and the
        intersection's own resistance r_j, the mean of mu_f / (2 k_n) over
        the faults that meet there (their normal permeabilities' harmonic
        mean): 1/h_i = (d_i / t_i + r_j) / |e|."""
        t = [self._conductance(conduit) for conduit in self.faults]
        links = []
        for index, j in enumerate(self.junctions):
            r = self._junction_resistance(j)
            h = [j.measure / (d / t[f][k] + r) for f, k, d in zip(j.faults, j.cells, j.distances)]
            total = sum(h)
            for a in range(len(h)):
                for b in range(a + 1, len(h)):
                    fa, fb = j.faults[a], j.faults[b]
                    links.append(((self.faults[fa].offset + j.cells[a], self.faults[fb].offset + j.cells[b]),
                                  (fa, fb), h[a] * h[b] / total, j.point, index))
        return links

    def _held_ends(self, conduit):
        """The ends on pressure boundaries: (indices into the ends, T_e)."""
        cells = conduit.cells
        held = [e for e, g in enumerate(cells.end_groups) if g in self.pressure_boundaries]
        return held, transmissibilities(self._conductance(conduit), cells.ends)[held]

    def operator_matrix(self, dt):
        """C: the fault's rows against its own unknowns (collective)."""
        C = PETSc.Mat().createAIJ(((self.owned, None), (self.owned, None)), comm=self.comm)
        C.setPreallocationNNZ((8, 8))
        # 8 per row is a guess: a cell by a junction couples to every member
        # of its star (four faults through one point: 9 entries).
        C.setOption(PETSc.Mat.Option.NEW_NONZERO_ALLOCATION_ERR, False)
        row = self.rows.row

        def add(k, l, value):  # each rank sets its own rows
            if self.rows.owns(k):
                C.setValue(row[k], row[l], value, addv=True)

        for conduit in self.faults:
            cells, t, o = conduit.cells, self._conductance(conduit), conduit.offset
            diagonal = -self._storage(conduit, dt) - self._stabilisation(conduit, dt)
            T = transmissibilities(t, conduit.links)
            for (k, l), T_kl in zip(conduit.links.cells.tolist(), T):
                add(o + k, o + k, -T_kl), add(o + k, o + l, T_kl), add(o + l, o + k, T_kl), add(o + l, o + l, -T_kl)
            held, T_e = self._held_ends(conduit)
            np.subtract.at(diagonal, cells.ends.cells[held, 0], T_e)
            for k, value in enumerate(diagonal):
                add(o + k, o + k, value)
        for (a, b), _, T_ab, _, _ in self._junction_links():
            add(a, a, -T_ab), add(a, b, T_ab), add(b, a, T_ab), add(b, b, -T_ab)
        C.assemble()
        return C

    def set_openings(self, opening, traction):
        """The hydraulic apertures w_h = w_r + b(s_n) + (w - e)^+ of the
        cells' mean openings w (FaultAperture.opening) and effective normal
        stresses s_n (FaultAperture.cell_means of the contact tractions; None
        without a closure) of the last mechanics iterate, every cell on every
        rank: b the closure's share (closure_aperture, 0 without one), e =
        OPEN_FRACTION w_r; and which cells are open (w > e; pinned cells as
        pinned). The first call of a run also sets the start's apertures.
        Whether w_h or an open cell changed (the operator, the resistance)."""
        changed, flipped_back, largest, change = False, False, 0.0, 0.0
        for conduit in self.faults:
            o, n, e = conduit.offset, len(conduit.cells.measures), OPEN_FRACTION * conduit.residual
            if conduit.closure and traction is not None and len(traction):  # none before the first solve: u = 0
                conduit.traction = np.asarray(traction[o:o + n], dtype=float)
            closed = closure_aperture(conduit.closure, conduit.traction) if conduit.closure else 0.0
            opened, is_open, free = self._pinned_openings(conduit, opening[o:o + n], e)
            w_h = conduit.residual + closed + opened
            flipped_back = flipped_back or (self.lagged and bool(np.any((is_open != conduit.open) & free
                                                                         & (is_open == conduit.open_before))))
            changed = (changed or not np.array_equal(w_h, conduit.aperture)
                       or not np.array_equal(is_open | conduit.open, conduit.open | conduit.open_before))
            largest = max(largest, w_h.max(initial=0.0))
            change = (np.inf if np.any(is_open != conduit.open)
                      else max(change, np.abs(w_h - conduit.aperture).max(initial=0.0)))
            conduit.aperture, conduit.open_before, conduit.open = w_h, conduit.open, is_open
            self._set_compliance(conduit)
            if not self.started:
                conduit.aperture_start = conduit.aperture.copy()
                conduit.aperture_before = conduit.aperture.copy()
        self.started = True
        self.relaxing = self.relaxing or flipped_back
        moved = self._relax_conducting()
        # how far the apertures moved: the largest change relative to the
        # largest aperture (or the lag of the conducting ones), infinite where
        # a cell opened or closed
        self.aperture_change = max(change, moved) / largest
        return changed or moved > 0

    def _relax_conducting(self):
        """Moves the apertures of the cubic law toward w_h; returns how far w_h lay from them (the lag r = w_h -
        conducting, m). Taken whole until a cell's open state flips back in this step (set_openings: the cubic
        law cycling) or the lag shrinks by less than RELAXED_ABOVE (in the split: grew at STALLED_ITERATIONS
        iterations in a row); from then to the step's end by Aitken's factor omega = -omega (r_old . (r -
        r_old)) / |r - r_old|^2, clamped to [1e-3, 1]. A negative factor: the monolithic step takes the lag
        whole with Newton's term (newton, flux_jacobian; dropped for the step's rest where the lag grows under
        it), the split the factor's magnitude; below the openings' round-off the factor's sign is noise, and in
        the split a lag that stagnates there (_stagnant) is held at the floor (theory.md, "Flow in a fault")."""
        dot = norm = lag = lag_old = moved = round_off = 0.0
        for conduit in self.faults:
            round_off = max(round_off, OPEN_FRACTION * conduit.residual)  # as set_openings's
            if conduit.conducting is None:
                conduit.conducting, conduit.lag = conduit.aperture.copy(), np.zeros_like(conduit.aperture)
            r = conduit.aperture - conduit.conducting
            d = r - conduit.lag
            dot += float(conduit.lag @ d)
            norm += float(d @ d)
            lag += float(r @ r)
            lag_old += float(conduit.lag @ conduit.lag)
        # The split's lag shrinks at the coupling's rate, after a transient: there only a lag that grew at
        # STALLED_ITERATIONS iterations in a row counts. The monolithic step's first lag grew from none (w_c = w_h
        # at the start): it relaxes from there at Aitken's floor (its factor 0: no lag before), a cautious first
        # move the opening needs (taken whole, fault_reactivation opened at 1e-3 m^2/s cycles with period 3).
        stalled = self.lagged and lag > (RELAXED_ABOVE ** 2 if self.implicit else 1.0) * lag_old
        self.stalled = self.stalled + 1 if stalled else 0
        self.relaxing = self.relaxing or self.stalled >= (1 if self.implicit else STALLED_ITERATIONS)
        if self.newton and stalled and math.sqrt(lag) > round_off:  # the lag grew under Newton's term
            self.newton, self.overshot, self.relaxation = False, True, self.relaxed
        elif self.relaxing and norm > 0 and not self.newton:
            aitken = -self.relaxation * dot / norm
            self.newton = self.implicit and aitken < 0 and not self.overshot
            self.relaxed = self.relaxation
            noise = math.sqrt(lag) <= round_off
            self.relaxation = 1.0 if self.newton else min(max(aitken if noise else abs(aitken), 1e-3), 1.0)
            self.held = self.held or (noise and self._stagnant(math.sqrt(lag)) and not self.implicit)
            self.relaxation = 1e-3 if self.held else self.relaxation
        for conduit in self.faults:
            conduit.lag = conduit.aperture - conduit.conducting
            conduit.conducting = conduit.conducting + self.relaxation * conduit.lag
            moved = max(moved, np.abs(conduit.lag).max(initial=0.0))
        self.lagged = True
        self.lags.append(math.sqrt(lag))
        return moved

    def drop_newton(self):
        """Leaves Newton's term for the rest of the step where a solve with it failed: the conducting apertures
        back to the relaxation it began from, w_c = w_c^old + omega lag (the last _relax_conducting took the lag
        whole)."""
        for conduit in self.faults:
            conduit.conducting = conduit.conducting - (1 - self.relaxed) * conduit.lag
        self.newton, self.overshot, self.relaxation = False, True, self.relaxed

    def _stagnant(self, lag):
        """Whether `lag` (|w_h - w_c|) has not halved over the last
        LAG_WINDOW iterations of the step."""
        return len(self.lags) >= LAG_WINDOW and lag > 0.5 * self.lags[-LAG_WINDOW]

    def without_stabilisation(self):
        """No fixed-stress term from now on (the second pass of
        "multirate-two-pass", which solves without L)."""
        self.stabilised = False

    def with_implicit_openings(self):
        """The open cells' opening is an unknown of the same system (the
        monolithic step, whose rows -(|k|/dt) J u carry it: opening_rates):
        they take no fixed-stress term; closed cells keep their closure's."""
        self.implicit = True

    def opening_rates(self, step, p_old, p_iterate):
        """Per appended row (this rank's entries) the factor of the cell's
        mean opening in its mass balance at iterate i, -(|k|/dt) (1 + c_f
        (p^i - p^old)) (p^old the history value of the FineStep `step`)
        where the cell was open at the last set_openings (the volume it
        opens, and Newton's term of its fluid's storage c_f w_h (p - p^old)
        in w_h), 0 where closed (collective)."""
        p_star = self._pressure_history(step, self.rows.everywhere(p_old))
        p = self.rows.everywhere(p_iterate)
        if not self.size:
            return np.zeros(0)
        is_open = np.concatenate([conduit.open for conduit in self.faults])
        measures = np.concatenate([conduit.cells.measures for conduit in self.faults])
        factor = 1 + self.flow.c_f * (p - p_star)
        return self.rows.entries(np.where(is_open, -measures / step.dt * factor, 0.0))

    def _pressure_history(self, step, p_old):
        """The history value of the pressure p_old (every cell) at `step`."""
        return history_value(step, p_old, p_old if self.pressure_before is None else self.pressure_before)

    def _aperture_history(self, conduit, step):
        """The history value of the conduit's apertures at `step`."""
        return history_value(step, conduit.aperture_start, conduit.aperture_before)

    def begin_step(self):
        """A step starts: no cell was open at an iterate before (the next
        set_openings's)."""
        for conduit in self.faults:
            conduit.open = np.zeros_like(conduit.open)
            conduit.pinning = CellPins(len(conduit.open))
            if conduit.conducting is not None:  # the step starts from w_h, as a restart does
                conduit.conducting = conduit.aperture.copy()
        # The relaxation of the conducting apertures (_relax_conducting): no lag of this step known yet, taken
        # whole; Newton's term of the transmissibilities off (newton: the conducting apertures follow w_h
        # whole from a negative Aitken factor on, cpp/assembly/fault_flow.h) and not dropped (overshot); not
        # held at the floor (held: the lag stagnated below round-off); the lags |w_h - w_c| of the step's
        # iterations, and how many in a row did not shrink.
        self.lagged = self.relaxing = self.newton = self.held = self.overshot = False
        self.lags, self.relaxation, self.stalled = [], 1.0, 0

    def load(self, step, p_old, p_iterate, b):
        """The fault's right-hand side of the FineStep `step` into b (its
        owned entries): -(S/dt) p_old - (L/dt) p_iterate - T_e p_D at the
        ends on pressure boundaries, -R(t) share in the cells a well meets
        (injection positive), and the fine step's share of the volume the
        cell's opening made since the start of the window, |k| (w_h -
        w_h_start)/(q dt). In a coupled split p_iterate is the last flow
        iterate's p^i, and w_h the last mechanics iterate's (collective).
        Every cell's entry on every rank (few), then this rank's."""
        t, dt = step.t, step.dt
        p_star = self._pressure_history(step, self.rows.everywhere(p_old))
        p_iterate = self.rows.everywhere(p_iterate)
        every = np.zeros(self.size)
        for conduit in self.faults:
            cells, o, n = conduit.cells, conduit.offset, len(conduit.cells.measures)
            part = (-self._storage(conduit, dt) * p_star[o:o + n]
                    - self._stabilisation(conduit, dt) * p_iterate[o:o + n]
                    + cells.measures * (conduit.aperture - self._aperture_history(conduit, step)) / (step.q * dt))
            held, T_e = self._held_ends(conduit)
            np.subtract.at(part, cells.ends.cells[held, 0], T_e * self._end_pressures(conduit, held, t))
            every[o:o + n] = part
        for row, share, rate, _ in self.wells:
            every[row] -= share * float(rate(0, 0, 0, t))
        b[:] = self.rows.entries(every)

    def _end_pressures(self, conduit, held, t):
        """p_D at the ends `held` at time t."""
        cells = conduit.cells
        return np.array([float(self.pressure_boundaries[cells.end_groups[e]](*cells.ends.points[e], t))
                         for e in held])

    def _mean_flux(self, conduit, pressure, junction_links, t):
        """Per cell the mean cubic-law flux, sum_e F_e (m_e - x_k) / |k|,
        with F_e the two-point flux out of the cell through its edge e (the
        mean of the lowest-order Raviart-Thomas field of those fluxes);
        `pressure` every conduit's, `junction_links` the junctions' links
        (_junction_links)."""
        cells, c = conduit.cells, self._conductance(conduit)
        p = pressure[conduit.offset:conduit.offset + len(cells.measures)]
        q = np.zeros((len(cells.measures), 3))
        links = conduit.links
        F = transmissibilities(c, links) * (p[links.cells[:, 0]] - p[links.cells[:, 1]])
        for side, sign in ((0, 1.0), (1, -1.0)):
            k = links.cells[:, side]
            np.add.at(q, k, sign * F[:, None] * (links.points - cells.centroids[k]))
        held, T_e = self._held_ends(conduit)
        k = cells.ends.cells[held, 0]
        F_e = T_e * (p[k] - self._end_pressures(conduit, held, t))
        np.add.at(q, k, F_e[:, None] * (cells.ends.points[held] - cells.centroids[k]))
        self_index = self.faults.index(conduit)
        for rows, faults, T_ab, point, _ in junction_links:
            F = T_ab * (pressure[rows[0]] - pressure[rows[1]])
            for side, sign in ((0, 1.0), (1, -1.0)):
                if faults[side] == self_index:
                    k = rows[side] - conduit.offset
                    q[k] += sign * F * (point - cells.centroids[k])
        return q / cells.measures[:, None]

    def cell_values(self, w, p, t):
        """The conduit cells' fields at time t, every fault in turn, on rank 0
        (None elsewhere; collective): columns pressure, hydraulic aperture,
        exchange (the rock's volume rate per area into the fault, sum_i c_i
        z_i / |k|) and mean flux (3). `w` the flow unknowns (this rank's),
        `p` the fault's pressure (this rank's entries)."""
        exchange = [(conduit.offset + k, c * w[dof - self.start]) for dof, conduit, k, c in self.faces]
        parts, p = self.comm.gather(exchange, root=0), self.rows.everywhere(p)
        if self.comm.rank != 0:
            return None
        values = np.zeros((self.size, 6))
        for rows in parts:
            for row, value in rows:
                values[row, 2] += value
        junction_links = self._junction_links()
        for conduit in self.faults:
            cells = slice(conduit.offset, conduit.offset + len(conduit.cells.measures))
            values[cells, 0], values[cells, 1] = p[cells], conduit.aperture
            values[cells, 2] /= conduit.cells.measures
            values[cells, 3:] = self._mean_flux(conduit, p, junction_links, t)
        return values

