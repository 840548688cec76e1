"""Newton's term of the conduit faults' transmissibilities
(cpp/assembly/fault_flow_jacobian.h; docs/theory.md "Flow in a fault",
"Newton on the cubic law"): the derivatives of the two-point
transmissibilities and of a junction's star by the cells' apertures, and
ConduitFaults' methods that assemble from them the derivative of each
cell's flux terms by the conducting apertures of the open cells, which the
monolithic step's rows carry so that its aperture iteration is a Newton
iteration on the cubic law."""
import numpy as np
from petsc4py import PETSc


def transmissibility_slopes(t, slope, edges):
    """The derivatives dT/dw of each of the FaultEdges' transmissibilities
    T = |e| / R, R = sum_k d_k/t_k (fault_flow.transmissibilities) by each of
    its cells' aperture, shaped like edges.cells: dT/dt_k = |e| d_k / (R^2
    t_k^2) times `slope`, dt/dw per cell."""
    R = np.sum(edges.distances / t[edges.cells], axis=1)
    return edges.measures[:, None] * edges.distances * slope[edges.cells] / (R[:, None] * t[edges.cells]) ** 2


def star_flux_derivative(h, p):
    """A junction's star: with its members' transmissibilities h to the
    intersection and pressures p, the intersection's p_j = sum h_i p_i /
    sum h_i, member a's flux term N_a = -h_a (p_a - p_j); returns dN_a/dh_c
    (a by c)."""
    h, p = np.asarray(h, dtype=float), np.asarray(p, dtype=float)
    S = h.sum()
    p_j = h @ p / S
    return -np.diag(p - p_j) + np.outer(h, p - p_j) / S


class ConduitJacobian:
    """Newton's term of ConduitFaults (assembly/fault_flow.py), its base
    class: the methods below read the faults' cells, links, ends and
    junctions that ConduitFaults holds."""

    def _conductance_slope(self, conduit):
        """dt/dw per cell at the conducting aperture where the cell is open, 0
        where closed and before newton: t = k_f w / mu_f (dt/dw = t/w) or w^3
        / (12 mu_f) (dt/dw = 3 t/w); a closed cell's w_h does not move with u
        (a closure's moves with s_n, explicit)."""
        w = conduit.aperture if conduit.conducting is None else conduit.conducting
        n = 1.0 if conduit.permeability > 0 else 3.0
        return np.where(np.logical_and(conduit.open, self.newton), n * self._conductance(conduit) / w, 0.0)

    def _junction_resistance(self, j):
        """The intersection's own resistance r_j at junction j: the mean of
        mu_f / (2 k_n) over the faults that meet there."""
        faults = sorted(set(j.faults))
        return sum(self.faults[f].normal_resistance / len(faults) for f in faults)

    def flux_jacobian(self, p, t):
        """Newton's term of the cubic law: D_km = dN_k/dw_m, the derivative of
        cell k's flux terms N_k = -sum_l T_kl (p_k - p_l) - sum_ends T_e (p_k
        - p_D) (junctions' links included) by the conducting aperture w_m of
        each cell m open at the last set_openings, at the faults' pressure `p`
        (this rank's entries) and time t (p_D); zero before newton. Entries
        of closed cells stay as zeros, so the structure does not change as
        cells open (collective)."""
        p = self.rows.everywhere(p)
        D = PETSc.Mat().createAIJ(((self.owned, None), (self.owned, None)), comm=self.comm)
        D.setPreallocationNNZ((8, 8))
        # 8 per row is a guess, as in operator_matrix (a junction's star).
        D.setOption(PETSc.Mat.Option.NEW_NONZERO_ALLOCATION_ERR, False)
        row = self.rows.row

        def add(k, m, value):  # each rank sets its own rows
            if self.rows.owns(k):
                D.setValue(row[k], row[m], value, addv=True)

        for k in range(self.size):
            add(k, k, 0.0)  # every diagonal entry: B = (rates + D) J's structure stays
        for conduit in self.faults:
            o, t_c, slope = conduit.offset, self._conductance(conduit), self._conductance_slope(conduit)
            # A link's N_k = -T (p_k - p_l), N_l = -T (p_l - p_k); entries kept
            # where closed (their slope 0).
            dT = transmissibility_slopes(t_c, slope, conduit.links)
            for e, (k, l) in enumerate(conduit.links.cells.tolist()):
                jump = p[o + k] - p[o + l]
                for i, m in enumerate((k, l)):
                    add(o + k, o + m, -dT[e, i] * jump)
                    add(o + l, o + m, dT[e, i] * jump)
            # An end's N_k = -T_e (p_k - p_D).
            dT_e = transmissibility_slopes(t_c, slope, conduit.cells.ends)
            held, _ = self._held_ends(conduit)
            p_D = self._end_pressures(conduit, held, t)
            for i, e in enumerate(held):
                k = o + int(conduit.cells.ends.cells[e, 0])
                add(k, k, -dT_e[e, 0] * (p[k] - p_D[i]))
        self._add_junction_jacobian(p, D)
        D.assemble()
        return D

    def _add_junction_jacobian(self, p, D):
        """Adds the junctions' share of flux_jacobian to D: member c reaches
        the junction with h_c = |e| / (d_c/t_c + r) (_junction_links), so
        dh_c/dt_c = h_c^2 d_c / (|e| t_c^2), and member a's flux term is the
        star's (star_flux_derivative)."""
        t = [self._conductance(conduit) for conduit in self.faults]
        slope = [self._conductance_slope(conduit) for conduit in self.faults]
        for j in self.junctions:
            r = self._junction_resistance(j)
            members = list(zip(j.faults, j.cells, j.distances))
            h = np.array([j.measure / (d / t[f][k] + r) for f, k, d in members])
            dh = np.array([h[i] ** 2 * d * slope[f][k] / (j.measure * t[f][k] ** 2)
                           for i, (f, k, d) in enumerate(members)])
            cells = [self.faults[f].offset + k for f, k, _ in members]
            dN = star_flux_derivative(h, [p[cell] for cell in cells])
            for a, cell in enumerate(cells):
                if self.rows.owns(cell):
                    D.setValues([self.rows.row[cell]], self.rows.row[cells], dN[a] * dh, addv=True)

    def conducting_lag(self):
        """w_h - w_c per cell, the hydraulic aperture's lead on the conducting
        one that _relax_conducting left (this rank's entries)."""
        if not self.size:
            return np.zeros(0)
        return self.rows.entries(np.concatenate([np.zeros(len(c.aperture)) if c.conducting is None
                                                 else c.aperture - c.conducting for c in self.faults]))
