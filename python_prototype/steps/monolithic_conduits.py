"""The conduit faults' pressure in the monolithic step
(cpp/steps/monolithic_conduits.h; docs/theory.md, "The monolithic solve
with p_f"): p_f, one unknown per fault cell, appended to x = (u, z, p),
    [[A + D, E], [B, C]] [x; p_f] = [b; b_f],
    E = B_z^T - J^T |k|   the faces' pressure p_f and its push on them
                          (fault_flow.py, fault_aperture.py), 0 on Dirichlet rows;
    B = B_z + M J         the exchange and the open cells' opening (J: the
                          cells' mean jump), M = G - (|k|/dt) O, G Newton's
                          term of their transmissibilities;
    C                     the fault's own rows (fault_flow.py), no
                          fixed-stress term in open cells."""
import dataclasses

import math

import numpy as np
from dolfinx import fem
from mpi4py import MPI
from petsc4py import PETSc

from ..assembly.fault_aperture import FaultAperture
from ..assembly.fault_flow import ConduitFaults, FineStep
from ..assembly.linear_algebra import owned, placement
from ..contact.contact_state import pair_tractions
from ..scene.input import FaultFlow
from ..time.time_scheme import TimeDerivative
from .system import AppendedUnknowns


@dataclasses.dataclass
class MixedSpace:
    """The monolithic step's mixed space X and where its parts sit: the
    displacement space V, its DOFs' places in X, the Dirichlet conditions on
    X and the facet flux of X's flux basis functions."""
    X: object
    V: object
    V_to_X: object
    bcs: list
    flux: object


class MonolithicConduits:
    """The conduit faults of the monolithic step: their rows of the coupled
    system and the iteration on their apertures.

    Which cells are open, their transmissivity and a closure's aperture
    follow the solution: each step iterates on them. At iterate i, b_f holds
    the volume with its open cells' opening taken at u^i, and Newton's term
    of the transmissibilities, G (J u^i - (w_h^i - w_c)) with G = dN/dw_c at
    p_f^i (ConduitFaults.flux_jacobian), which the solve moves to u^{i+1}: a
    Newton iteration on the open cells' apertures, from the conducting ones
    w_c. Closed cells keep their closure's fixed-stress term, which vanishes
    as p_f settles. The iteration stops when the apertures and p_f move by
    at most the coupling's tolerance."""

    def __init__(self, problem, space):
        self.problem = problem
        faults = ConduitFaults(problem.scene, problem.domain, space.X.sub(1), space.flux)
        self.faults = faults if faults else None
        self.derivative = TimeDerivative()  # of the step (set_time_derivative)
        self.G = None     # Newton's term of the transmissibilities at the last append (flux_jacobian)
        self.time = 0.0   # of the last load: the held ends' p_D in G
        if not faults:
            return
        faults.with_implicit_openings()
        self.pressure = faults.initial_pressure(problem.scene.flow.initial_pressure)
        self.pressure_old = self.pressure.copy()
        self.aperture = FaultAperture(problem.scene, problem.domain, space.V)
        R = placement(space.V, space.V_to_X, space.X)
        self.J = self.aperture.J.matMult(R)
        self.cells = self.J.createVecLeft()
        self.rows = owned(space.X)
        self.E = self._load_rows(space)

    def _load_rows(self, space):
        """E = B_z^T - J^T |k|, zero on the Dirichlet rows (whose equations are
        x_i = g_i alone), once: neither the faces nor J change with the
        apertures."""
        ones = fem.Function(space.X)
        ones.x.array[:] = 1.0
        fem.set_bc(ones.x.array, space.bcs, scale=0.0)
        no_bcs = self.J.createVecRight()
        no_bcs.array[:] = ones.x.array[:self.rows]
        measures = self.cells.duplicate()
        measures.array[:] = -self.aperture.measures  # this rank's cells, as J's rows
        Jt = self.J.transpose(PETSc.Mat())
        Jt.diagonalScale(None, measures)
        E = self.faults.exchange(self.rows).transpose(PETSc.Mat())
        E.axpy(1.0, Jt, structure=PETSc.Mat.Structure.DIFFERENT_NONZERO_PATTERN)
        E.diagonalScale(no_bcs, None)
        return E

    def __bool__(self):
        return self.faults is not None

    def has_closure(self):
        """The closure needs the faults' contact tractions after each solve."""
        return any(f.flow == FaultFlow.conduit and f.closure for f in self.problem.scene.faults.values())

    def _step(self, t):
        """The FineStep of the step to t: the "dt" constant and the derivative."""
        return FineStep(t, float(self.problem.forms["dt"].value), 1, 1, self.derivative.coefficients())

    def set_time_derivative(self, system, d):
        """The step's time derivative (MonolithicStep.solve's): the faults'
        storage differentiates with it as the rock's (time_scheme.py); the
        rows appended again if it changed."""
        changed = d.coefficients() != self.derivative.coefficients()
        self.derivative = d
        if changed:
            self.append(system)

    def append(self, system):
        """Appends the rows at the current apertures and dt to `system` (again
        after a change: the same structure)."""
        B_z = self.faults.exchange(self.rows)
        # B = B_z + M J, M = G - (|k|/dt) O: Newton's term of the open cells'
        # transmissibilities (G at this iterate's p_f, kept for load's
        # right-hand side) and their opening rate (opening_rates); every entry
        # of J and G kept, zero where closed, so the structure stays as cells
        # open and close.
        self.G = self.faults.flux_jacobian(self.pressure, self.time)
        M = self.G.copy()
        factors = self.cells.duplicate()
        factors.array[:] = self.faults.opening_rates(self._step(0.0), self.pressure_old, self.pressure)
        M.setDiagonal(factors, addv=PETSc.InsertMode.ADD_VALUES)
        B = M.matMult(self.J)
        B.axpy(1.0, B_z, structure=PETSc.Mat.Structure.DIFFERENT_NONZERO_PATTERN)
        # The fixed-stress preconditioner's C (iterative path) takes the
        # split's term -L_k/dt in the open cells, whose opening it leaves to
        # the mechanics (alg. "Single-rate ... (a)" on the fault).
        dt = self._step(0.0).dt
        system.append(AppendedUnknowns(B, self.faults.operator_matrix(dt), self.faults.face_resistance(),
                                       np.zeros(self.faults.owned), self.pressure.copy(), self.E.copy(),
                                       -self.faults.open_stabilisation(dt)))

    def begin_step(self, system, u, s_n):
        """The step starts from the displacement u (a Function of V) and the
        cells' effective normal stress `s_n` (None before any contact solve):
        p_f now is the step's p_f^old, and the apertures are u's."""
        self.faults.begin_step()
        self.pressure_old = self.pressure.copy()
        self.faults.set_openings(self.aperture.opening(u), s_n)
        self.append(system)

    def load(self, system, x, t):
        """b_f of iterate i at time t from x = x^i (a vector of X), and p_f^i
        as the guess."""
        self.time = t
        appended = system.appended
        self.faults.load(self._step(t), self.pressure_old, self.pressure, appended.b)
        # The open cells' volume at u^i, which B's rows move to u^{i+1}, and
        # Newton's term at u^i: G (J u^i - (w_h - w_c)), the
        # transmissibilities' change from the conducting apertures w_c to
        # w_h(u^{i+1}).
        self.J.mult(x, self.cells)
        appended.b[:] += self.faults.opening_rates(self._step(0.0), self.pressure_old, self.pressure) * self.cells.array_r
        self.cells.array[:] -= self.faults.conducting_lag()
        newton = self.cells.duplicate()
        self.G.mult(self.cells, newton)
        appended.b[:] += newton.array_r
        appended.x[:] = self.pressure

    def update(self, system, u, s_n):
        """After a solve: p_f from `system`, the apertures from u and s_n, the
        rows appended again unless converged. Whether the iteration has
        converged."""
        before = self.pressure
        self.pressure = system.appended.x.copy()
        self.faults.set_openings(self.aperture.opening(u), s_n)
        moved = np.array([np.abs(self.pressure - before).max(initial=0.0), np.abs(self.pressure).max(initial=0.0)])
        # A NaN would make MPI's maximum differ between ranks: the change is
        # infinite then, on every rank (cpp/steps/monolithic_conduits.cpp).
        if not np.all(np.isfinite(self.pressure)):
            moved[0] = np.inf
        self.problem.domain.mesh.comm.Allreduce(MPI.IN_PLACE, moved, op=MPI.MAX)
        tolerance = self.problem.scene.coupling.tolerance
        # The apertures' change (ConduitFaults.aperture_change) and p_f's
        # largest change relative to the largest p_f, for an error.
        self._change = (self.faults.aperture_change, moved[0] / moved[1] if moved[1] > 0 else moved[0])
        converged = (self.faults.aperture_change <= tolerance and np.isfinite(moved[0])
                     and moved[0] <= tolerance * moved[1])
        if not converged:  # the next iterate's rows: its apertures, and B's Newton term at its p_f
            self.append(system)
        return converged

    def newton(self):
        """Whether the rows carry Newton's term of the transmissibilities."""
        return self.faults.newton

    def drop_newton(self, system):
        """A solve with Newton's term of the transmissibilities failed: the
        rows again without it (ConduitFaults.drop_newton)."""
        self.faults.drop_newton()
        self.append(system)

    def last_change(self):
        """What the last update measured against the tolerance, for an error."""
        w, p = self._change
        cells = "a cell opened or closed" if math.isinf(w) else "no cell opened or closed"
        return (f"the last iteration moved the apertures by {w:g} relative ({cells}) and p_f by {p:g} relative, "
                f"against coupling.tolerance = {self.problem.scene.coupling.tolerance:g}")

    def normal_stress(self, state):
        """The cells' mean contact traction, s_n (every cell on every rank;
        collective)."""
        return self.aperture.cell_means(pair_tractions(state))

    def accept(self, x, t):
        """The accepted step to t: the volumes take it (`x` the coupled
        unknowns)."""
        step = self._step(t)
        self.faults.add_volumes(self.faults.step_volumes(x, self.pressure, self.pressure_old, step), step,
                                self.pressure_old)
        self.faults.set_intersection_rates(self.pressure)

    def unbalanced(self, x, t, rock_flux):
        """A fault that the step to t would leave unbalanced, or empty
        (`rock_flux` the rock's largest flux DOF: ConduitFaults.unbalanced)."""
        return self.faults.unbalanced(self.faults.step_volumes(x, self.pressure, self.pressure_old,
                                                               self._step(t)), rock_flux)

    def cell_values(self, x, t):
        """The faults' cell fields at t on rank 0 (ConduitFaults.cell_values)."""
        return self.faults.cell_values(x, self.pressure, t)

    def volumes(self):
        return self.faults.volumes()

    def intersection_rates(self):
        return self.faults.intersection_rates()

    def keep(self, arrays):
        """p_f, the volumes and the start apertures as a checkpoint keeps them
        (FlowStep.arrays' names)."""
        arrays.update(self.faults.arrays(self.pressure))

    def restore(self, arrays):
        self.faults.restore_arrays(arrays, self.pressure)
