"""A run of one scene (cpp/simulation.cpp): scene -> mesh and tags -> forms ->
flow step / mechanics step (or the monolithic step) -> coupling scheme ->
output and diagnostics."""
import os
import sys

import numpy as np
from dolfinx import fem

from .output.checkpoint import (Checkpoint, keyed_values, mesh_difference, mesh_signature, read_checkpoint,
                                restore_values, write_checkpoint)
from .diagnostics.closed_form import Mandel, Terzaghi
from .domain.domain import check_expressions, create_domain
from .coupling.coupling import CouplingError, CouplingReport, WindowObserver, for_each_checkpointed
from .coupling.fixed_stress import run_fixed_stress
from .coupling.single_solve import run_single_solve
from .coupling.step_control import StepControl
from .assembly.forms import Forms
from .assembly.linear_algebra import UnknownsPart
from .assembly.materials import gamma_warning, make_materials
from .assembly.parameters import derive_parameters, set_constants
from .output.directory_lock import DirectoryLock
from .scene.scene import SceneError
from .output.output import Output
from .output.write_failure import OutputError
from .output.progress import Progress, is_rank0
from .contact.contact import ContactState
from .output.interruption import interruption_signal
from .steps.time_grid import time_grid
from .solvers.solver import Method, SolverError, SolverStatistics, solver_counts
from .diagnostics.diagnostics import ContractionNorm, relative_error, volumetric_stress
from .steps.flow_step import FlowStep
from .steps.mechanics_step import MechanicsStep
from .steps.monolithic_step import MonolithicStep

RUN_OK, RUN_NOT_CONVERGED, RUN_OUTPUT_FAILED = 0, 3, 4


def global_size(V):
    return V.dofmap.index_map.size_global * V.dofmap.index_map_bs


def boundary_mean(u, facets, component, comm):
    """Mean of one displacement component over the nodes of a boundary (collective)."""
    V = u.function_space
    dofs = fem.locate_dofs_topological(V.sub(component), V.mesh.topology.dim - 1, facets)
    dofs = dofs[dofs < V.dofmap.index_map.size_local * V.dofmap.index_map_bs]
    total, count = comm.allreduce(np.array([u.x.array[dofs].sum(), len(dofs)]))
    return total / count


def contact_json(c):
    return {"contact_nodes": c.contact_nodes, "active_nodes": c.active_nodes,
            "max_penetration": c.max_penetration, "max_complementarity": c.max_complementarity,
            "max_contact_pressure": c.max_pressure, "min_contact_pressure": c.min_pressure,
            "gap_scale": c.gap_scale, "total_force": c.total_force,
            "boundaries": {name: {"force": force, "active_nodes": active} for name, force, active in c.boundaries}}


def closed_form_errors(scene, parameters, F, domain, u, p, comm):
    """The relative L2 errors (and Terzaghi's settlement) at the final time
    against the scene's closed form, Terzaghi or Mandel."""
    ref, fs = scene.reference, scene.flow
    mobility = fs.permeability(0, 0, 0, 0) / fs.mu_f
    t, y0 = scene.end_time, scene.mesh.lower[1]
    # The closed form: pressure and displacement at the points x.
    terzaghi = None
    if ref.solution == "terzaghi":
        terzaghi = Terzaghi(ref.height, parameters.G, parameters.lmbda, parameters.alpha, parameters.storage, mobility,
                            ref.load)
        p_exact = lambda x: terzaghi.pressure(x[1] - y0, t)  # noqa: E731
        u_exact = lambda x: [0.0 * x[0], terzaghi.displacement(x[1] - y0, t)]  # noqa: E731
    else:
        mandel = Mandel(scene.mesh.upper[0], scene.mesh.upper[1], parameters.G, parameters.lmbda, parameters.alpha,
                        parameters.storage, mobility, ref.force)
        p_exact = lambda x: mandel.pressure(x[0], t)  # noqa: E731
        u_exact = lambda x: [mandel.displacement_x(x[0], t), mandel.displacement_y(x[1], t)]  # noqa: E731
    F["p_reference"].interpolate(p_exact)
    F["u_reference"].interpolate(lambda x: np.vstack(u_exact(x)))
    F["p_out"].x.array[:] = p.x.array
    F["u_out"].x.array[:] = u.x.array
    errors = {
        "time": t,
        "pressure_rel_l2": relative_error(F, F.compile("M_pressure_error"),
                                          F.compile("M_pressure_reference"), comm),
        "displacement_rel_l2": relative_error(F, F.compile("M_displacement_error"),
                                              F.compile("M_displacement_reference"), comm)}
    if terzaghi:
        settlement = -boundary_mean(u, domain.boundaries["top"], 1, comm)
        exact = terzaghi.settlement(t)
        errors.update({"settlement": settlement, "settlement_exact": exact,
                       "settlement_rel": abs(settlement - exact) / abs(exact)})
    return errors


def equilibrate(scene, domain, F, mechanics, monolithic):
    """mechanics.initial_equilibrium: replaces u = 0 by the displacement in
    equilibrium with the loads at t = 0 and the initial pressure (a geostatic
    initialisation). Otherwise loads present from the start, such as the
    in-situ stresses, are applied in the first step as a sudden load, whose
    undrained pressure response the first flow steps then carry."""
    if mechanics:
        mechanics.solve(0.0)
        return
    # The coupled system has no mechanics system of its own: one mechanics
    # step on its displacement space, loaded by its pressure, solved once.
    step = MechanicsStep(scene, domain, F, monolithic.pressure)
    step.solve(0.0)
    monolithic.set_displacement(step.u.x.array, 0.0)


def regions_json(cells, materials):
    """The regions of the summary: each one's cells and its material's gamma
    and L, and the cells in no region (the top-level material)."""
    regions = {name: {"cells": count, "gamma": m.gamma, "L": m.L}
               for name, count, m in zip(cells.names, cells.counts, materials.regions)}
    regions["no region"] = {"cells": cells.outside, "gamma": materials.top.gamma, "L": materials.top.L}
    return regions


class Steps:
    """The steps a scene has (each scene allocates only the physics it has),
    and the fields output and diagnostics read, whichever step produced them."""

    def __init__(self):
        self.flow = self.second_pass = None  # second_pass: "multirate-two-pass"
        self.mechanics = self.monolithic = None
        self.V = self.u = self.p = None
        self.contact_pressure = self.contact_active = self.contact_boundary = None
        self.compute_flux = None
        self.compute_contact = ContactState
        self.step_control = None  # time.adaptive

    def systems(self):
        """The systems by their summary name, in the order of checkpoints."""
        return [("flow", self.flow.system if self.flow else None),
                ("mechanics", self.mechanics.system if self.mechanics else None),
                ("monolithic", self.monolithic.system if self.monolithic else None),
                ("flow_second_pass", self.second_pass.system if self.second_pass else None)]

    def assembly_time(self):
        """Assembly time of the steps' loads and matrices."""
        t = 0.0
        for f in (self.flow, self.second_pass):
            t += f.assembly_time if f else 0.0
        t += self.mechanics.assembly_time if self.mechanics else 0.0
        return t + (self.monolithic.assembly_time if self.monolithic else 0.0)


def take_contact_fields(s, step):
    """The contact fields of a step that has them."""
    if not step.system.has_contact():
        return
    s.contact_pressure, s.contact_active = step.contact_pressure, step.contact_active
    s.contact_boundary = step.contact_boundary
    s.compute_contact = step.contact_state


def monolithic_steps(scene, domain, F):
    """The monolithic step: u, z and p in one system."""
    s = Steps()
    s.monolithic = m = MonolithicStep(scene, domain, F)
    s.V, s.u, s.p, s.compute_flux = m.V, m.u, m.pressure, m.flux
    take_contact_fields(s, m)
    return s


def split_steps(scene, domain, F, materials):
    """The flow step and the mechanics step of the split, or the one a single
    physics has; "multirate-two-pass" adds the flow step without L."""
    s = Steps()
    if scene.mechanics:
        s.V = F["V"]
    if scene.flow:
        s.flow = FlowStep(scene, domain, F, materials, coupled=scene.coupling is not None)
        s.p = s.flow.pressure
        if scene.coupling and scene.coupling.scheme == "multirate-two-pass":
            # The second pass is the flow step without the stabilisation L:
            # forms of its own, whose coefficient L is 0.
            unstabilised = Forms(domain.mesh)
            set_constants(unstabilised, scene, derive_parameters(scene))
            s.second_pass = FlowStep(scene, domain, unstabilised, materials.without_stabilisation(F, unstabilised),
                                     coupled=True)
        s.compute_flux = s.flow.flux
    if scene.mechanics:
        s.mechanics = MechanicsStep(scene, domain, F, s.p if scene.coupling is not None else None)
        s.u = s.mechanics.u
        take_contact_fields(s, s.mechanics)
    return s


class OutputFields:
    """The fields written at each output time: the unknowns and what is
    derived from them (cell-averaged flux, volumetric stress sigma_v, contact)."""

    def __init__(self, F, steps, output):
        self._F, self._steps, self._output = F, steps, output
        if steps.p is not None:
            steps.p.name = "pressure"
            self._flux = fem.Function(F["Qv"], name="flux")
        if steps.u is not None:
            steps.u.name = "displacement"
            self._sigma_v = fem.Function(F["Q"], name="sigma_v")
            self._L_sigma_v = F.compile("L_sigma_v")
            if steps.contact_pressure is not None:
                steps.contact_pressure.name = "contact_pressure"
                steps.contact_active.name = "contact_active"
        self.contact = ContactState()  # at the last mechanics output

    def write_flow(self, t):
        self._output.write(self._steps.p, t)
        self._steps.compute_flux(self._flux)
        self._output.write(self._flux, t)

    def write_mechanics(self, t):
        """Also updates `contact` (and the contact fields)."""
        s = self._steps
        self.contact = s.compute_contact()
        volumetric_stress(self._F, self._L_sigma_v, s.u, s.p, self._sigma_v)
        self._output.write(s.u, t)
        self._output.write(self._sigma_v, t)
        if s.contact_pressure is not None:
            self._output.write(s.contact_pressure, t)
            self._output.write(s.contact_active, t)


def capture_checkpoint(steps, time, s, mesh, report, output, grid, scene):
    """The state a restart needs after `steps` completed steps (checkpoint.py)."""
    c = Checkpoint(steps, time, output=output)
    # The grid as retries left it (the same on every rank).
    c.arrays["times"], c.arrays["time_steps"] = np.array(grid.t), np.array(grid.dt)
    c.arrays["mesh"] = mesh_signature(mesh)
    for parts, unknowns in unknowns_parts(s, scene):
        for part in parts:
            c.fields[part.name] = keyed_values(mesh, part, unknowns)
    for_each_checkpointed(report, lambda name, value: c.numbers.__setitem__(name, float(value)))
    for i, (_, system) in enumerate(s.systems()):
        if system is not None:
            st = system.statistics()
            c.numbers.update({f"{i}.{name}": float(getattr(st, name)) for name in solver_counts})
    return c


def window_steps_json(c, report):
    """coupling.q = "auto"'s part of summary.json: its settings, the
    windows' mean and largest q, the windows tried again with q = 1 (contact)."""
    return {"q_max": c.q_max, "q_tolerance": c.q_tolerance,
            "mean_q": report.fine_steps / report.windows if report.windows else 0.0,
            "largest_q": report.max_window_q, "q_rejections": report.q_rejections}


def adaptive_json(spec, report, grid):
    """time.adaptive's part of summary.json: the tolerance, the steps
    rejected or forced at dt_min, the contact breaks, the largest accepted
    estimate, the steps taken."""
    j = {"tolerance": spec.tolerance, "dt_min": spec.dt_min, "dt_max": spec.dt_max,
         "rejected_steps": report.rejected_steps, "forced_steps": report.forced_steps,
         "contact_breaks": report.contact_breaks,
         "max_error_estimate": report.max_error_estimate}
    taken = grid.dt[:report.windows]
    if taken:
        j.update(smallest_step=min(taken), largest_step=max(taken))
    return j


def history(s, scene):
    """The memory of the time scheme and of time.adaptive by checkpoint name
    (cpp/simulation.cpp): BDF2's state one step before the last completed
    one, the displacement one window before with coupling.q = "auto" (its
    last change), the step control's accepted states."""
    h = []
    if scene.time_scheme == "bdf2" and s.monolithic:
        h = [("pressure_before", s.monolithic.p_before), ("displacement_before", s.monolithic.u_before)]
    elif scene.time_scheme == "bdf2" and s.flow:
        h = [("pressure_before", s.flow.p_before)]
        if s.flow.u_before is not None:
            h += [("displacement_before", s.flow.u_before), ("displacement_path_before", s.flow.u_path_before)]
    elif scene.coupling and scene.coupling.q_auto and s.flow and s.flow.u_before is not None:
        h = [("displacement_before", s.flow.u_before)]
    return h + (s.step_control.history() if s.step_control else [])


def unknowns_parts(s, scene):
    """Each step's fields and the vector of unknowns they sit in; also the
    memory of BDF2 and of time.adaptive (history)."""
    result = [([UnknownsPart(name, f.function_space)], f.x.array) for name, f in history(s, scene)]
    if s.flow:
        result.append((s.flow.parts(), s.flow.unknowns()))
    if s.mechanics:
        result.append(([UnknownsPart("displacement", s.V)], s.mechanics.u.x.array))
    if s.monolithic:
        result.append((s.monolithic.parts(), s.monolithic.unknowns()))
    return result


def restore_unknowns(c, s, mesh, directory, scene):
    """Loads the stored unknowns into the steps, whatever the partition;
    refuses a checkpoint of another mesh, or one that lacks any of them
    (collective)."""
    difference = mesh_difference(c.arrays.get("mesh"), mesh_signature(mesh))
    if difference:
        raise SceneError(f"--restart {directory}: the checkpoint does not match this mesh ({difference})")
    for parts, unknowns in unknowns_parts(s, scene):
        for part in parts:
            stored = c.fields.get(part.name)
            missing = mesh.comm.allreduce(1 if stored is None else restore_values(mesh, part, stored, unknowns))
            if missing > 0:
                raise SceneError(f"--restart {directory}: the checkpoint does not match this mesh ({missing} "
                                 f"values of the {part.name} not in it)")
    if s.flow:
        s.flow.set_unknowns(s.flow.unknowns())
    if s.monolithic:
        s.monolithic.set_unknowns(s.monolithic.unknowns())


def restore_checkpoint(c, s, mesh, directory, report, grid, scene):
    """Loads a checkpoint into the steps, the report, the grid and the solver counts."""
    grid.t, grid.dt = list(c.arrays["times"]), list(c.arrays["time_steps"])
    restore_unknowns(c, s, mesh, directory, scene)
    for_each_checkpointed(report, lambda name, value: setattr(report, name, type(value)(c.numbers[name])))
    for i, (_, system) in enumerate(s.systems()):
        if system is not None:
            earlier = SolverStatistics()
            for name in solver_counts:
                setattr(earlier, name, int(c.numbers[f"{i}.{name}"]))
            system.add_earlier(earlier)


def solver_summaries(steps, inexact_coupling):
    """Per system: what solved it, how often it was set up (factorised) and
    solved, and where its time went; the solvers' and timings' tables."""
    solvers, timings = {}, {}
    for name, system in steps.systems():
        if system is None:
            continue
        st = system.statistics()
        direct = system.method == Method.direct
        j = {"solver": system.method.name, "chosen_by": system.method_reason, "method": system.description(), "unknowns": system.unknowns(),
             "solves": st.solves, "factorizations": st.setups if direct else 0,
             "preconditioner_setups": st.setups,
             "inexact_coupling": not direct and not steps.monolithic and inexact_coupling,
             "back_solves": st.back_solves, "linear_iterations": st.linear_iterations}
        if system.has_contact():
            j.update(newton_iterations=st.newton_iterations, active_set_changes=st.active_set_changes,
                     schur_columns=st.schur_columns)
        solvers[name] = j
        timings[name] = {"total": st.total_time, "setup": st.setup_time, "solve": st.solve_time,
                         "schur_complement": st.schur_time,
                         "other": st.total_time - st.setup_time - st.solve_time - st.schur_time,
                         "matrix_assembly": st.assembly_time}
    return solvers, timings


def statistics(steps):
    """The statistics of each system (zero for a system the scene has not)."""
    return {name: system.statistics() if system else SolverStatistics() for name, system in steps.systems()}


class Simulation:
    """One run of a scene, in the order of its story: make the domain, set up
    the steps, open the output, start or restore, the time loop, the summary
    and the exit status."""

    def __init__(self, scene, directory, comm, fingerprint="", restart=False):
        self.scene, self.directory, self.comm = scene, directory, comm
        self.fingerprint, self.restart = fingerprint, restart
        # output.progress_interval (seconds between lines within a step)
        self.progress = Progress(comm, scene.progress_interval)
        self.domain = self.F = self.parameters = None
        self.left_out, self.warnings = "", ""
        self.steps = self.resumed = self.lock = self.output = self.fields = self.grid = None
        self.report = CouplingReport()
        self.completed_steps = 0     # mechanics steps (windows) written
        self.completed_time = 0.0
        self.saved = 0               # the step of the last checkpoint
        self.checkpointing = False   # writing the checkpoint of the last completed step
        self.signal = 0              # the interruption that ended the run
        self.failure = ""            # why the run failed
        self.output_failed = False   # ... because a file could not be written

    def run(self):
        """The story of a run; the files are closed and the directory's lock
        released however it ends."""
        scene = self.scene
        try:
            self.make_domain()
            self.describe()
            self.steps = (monolithic_steps(scene, self.domain, self.F)
                          if scene.coupling and scene.coupling.scheme == "monolithic"
                          else split_steps(scene, self.domain, self.F, self.materials))
            if scene.adaptive:
                self.steps.step_control = StepControl(scene, self.steps.p.function_space if self.steps.p else None,
                                                      self.steps.V, self.comm)
            try:
                self.open_output()
                self.start_or_restore()
                self.time_loop()
            except OutputError as e:
                self.stop_at_output_failure(e)
            self.write_summary()
        finally:
            self.close_output()
        return self.exit_status()

    def make_domain(self):
        """The mesh and its tags, the forms on it, the derived parameters and
        the constants of the forms."""
        self.domain = create_domain(self.scene, self.comm)
        check_expressions(self.scene, self.domain, self.comm)
        self.F = Forms(self.domain.mesh)
        self.materials = make_materials(self.scene, self.domain, self.F)
        self.parameters = derive_parameters(self.scene)
        self.parameters.gamma = self.materials.gamma  # the largest of any cell
        set_constants(self.F, self.scene, self.parameters)

    def describe(self):
        """Says what the scene leaves out, and warns where the method is known
        to degrade instead of returning poor numbers silently (docs/stability.md)."""
        scene, d = self.scene, self.domain.dim
        left_out = []
        if not scene.flow:
            left_out.append("flow (no [flow] table): no flux or pressure unknowns")
        if not scene.mechanics:
            left_out.append("mechanics (no [mechanics] table): no displacement unknowns")
        if scene.mechanics and not scene.has_contact():
            left_out.append("contact solver (no contact boundary): linear mechanics solve")
        if scene.flow and not scene.flow.gravity:
            left_out.append("gravity")
        if scene.mechanics and not scene.mechanics.body_force and not scene.cellwise_body_force():
            left_out.append("body force")
        self.left_out = "; ".join(left_out)
        self.progress.say(f"biotcontact (python prototype): scene {scene.name} ({scene.file}), {d}D, "
                          f"{self.domain.mesh.topology.index_map(d).size_global} cells")
        self.progress.say("left out: " + (self.left_out or "nothing"))

        warnings = []

        def warn(what):
            warnings.append(what)
            self.progress.say("warning: " + what)
        regions, materials = self.domain.regions, self.materials
        for name, count, m in zip(regions.names, regions.counts, materials.regions):
            self.progress.say(f"region {name}: {count} cells" + (f", gamma = {m.gamma:f}" if scene.coupling else ""))
        for r, m in enumerate(materials.regions + [materials.top] if scene.mechanics else []):
            nu = m.lmbda / (2 * (m.lmbda + m.G))
            if nu > 0.49 and (r < len(regions.names) or regions.outside > 0):
                warn((f"region {regions.names[r]}: " if r < len(regions.names) else "")
                     + f"nu = {nu:f} > 0.49: P1 displacements lock as nu -> 0.5 "
                     "(too stiff a response, worse on coarse meshes)")
        if warning := gamma_warning(scene, materials.gamma_peak()):
            warn(warning)
        self.warnings = "; ".join(warnings)

    def open_output(self):
        """The checkpoint a restart goes on from, the output files (created,
        or those of the checkpoint's run) and the fields written into them."""
        # The lock first: nothing in the directory is read, created or
        # truncated while another run holds it. A restart of a directory that
        # does not exist is refused by read_checkpoint, without creating it.
        if not self.restart or os.path.isdir(self.directory):
            self.lock = DirectoryLock(self.comm, self.directory)
        self.grid = time_grid(self.scene)  # a retry (time.retry) halves some of its steps
        if self.restart:
            # Loaded before the files are opened: a checkpoint that does not
            # match is refused with the files as they were.
            self.resumed = read_checkpoint(self.comm, self.directory, self.fingerprint)
            restore_checkpoint(self.resumed, self.steps, self.domain.mesh, self.directory, self.report, self.grid,
                               self.scene)
        self.output = Output(self.comm, self.directory, self.domain.mesh, self.scene.write_xdmf,
                             self.resumed.output if self.resumed else None)
        self.fields = OutputFields(self.F, self.steps, self.output)

    def close_output(self):
        """The files closed and the directory's lock released."""
        if self.output is not None:
            self.output.close()
        if self.lock is not None:
            self.lock.release()

    def start_or_restore(self):
        """The initial state, written at t = 0, or the state of the checkpoint."""
        s = self.steps
        if self.resumed:
            self.saved = self.completed_steps = self.resumed.steps
            self.completed_time = self.resumed.time
            if s.u is not None:
                self.fields.contact = s.compute_contact()
            self.progress.say(f"restarted from the checkpoint at step {self.completed_steps}, "
                              f"t = {self.completed_time:f}")
            return
        if self.scene.mechanics and self.scene.mechanics.initial_equilibrium:
            equilibrate(self.scene, self.domain, self.F, s.mechanics, s.monolithic)
        if s.p is not None:
            self.fields.write_flow(0.0)
        if s.u is not None:
            self.fields.write_mechanics(0.0)
        if s.contact_boundary is not None:
            self.output.write(s.contact_boundary, 0.0)  # once: every later time repeats it
        if s.step_control:
            s.step_control.start(s.p.x.array if s.p else None, s.u.x.array if s.u else None, self.report)

    def stop(self):
        """After each completed (and written) step: a checkpoint every
        checkpoint_every steps and at an interruption; then whether to stop."""
        def save():
            self.checkpointing = True
            write_checkpoint(self.comm, self.directory, self.fingerprint,
                             capture_checkpoint(self.completed_steps, self.completed_time, self.steps, self.domain.mesh,
                                                self.report, self.output.position(), self.grid, self.scene))
            self.checkpointing = False
            self.saved = self.completed_steps
        every = self.scene.checkpoint_every
        if every > 0 and self.completed_steps % every == 0:
            save()
        self.signal = interruption_signal(self.comm)
        if self.signal and every > 0 and self.saved != self.completed_steps:
            save()
        return self.signal != 0

    def observer(self):
        """What the coupling schemes tell the run: write each step, print the
        progress, checkpoint, stop at an interruption."""
        def flow_state(t):
            if self.scene.is_output_time(t):
                self.fields.write_flow(t)

        def mechanics_state(t, step, iterations):
            if self.steps.u is not None and self.scene.is_output_time(t):
                self.fields.write_mechanics(t)
            elif self.steps.u is not None:
                self.fields.contact = self.steps.compute_contact()
            self.completed_steps, self.completed_time = step, t
            self.progress.step(step, self.planned_steps(), t, iterations,
                               self.fields.contact.active_nodes)

        def iteration(step, iteration, dp, du):
            self.progress.heartbeat(f"step {step}: coupling iteration {iteration}, increments dp {dp:.3g} "
                                    f"du {du:.3g}")
        return WindowObserver(flow_state=flow_state, mechanics_state=mechanics_state, stop=self.stop,
                              retry=self.progress.say, iteration=iteration)

    def report_newton_steps(self):
        """A contact solve longer than the interval (a large monolithic step)
        prints its Newton steps as it goes, like the coupling iterations of
        the split: the contact solver calls on_newton_step(iteration) after
        each Newton step."""
        for name, system in self.steps.systems():
            if system is not None and system.has_contact():
                system.contact.on_newton_step = lambda iteration, name=name: self.progress.heartbeat(
                    f"step {self.completed_steps + 1}: {name} contact Newton step {iteration}")

    def time_loop(self):
        """The steps from t = 0 (or the checkpoint) to the end: the
        fixed-stress split, or one solve per step. A failure ends the loop
        with what was finished written; it names the step it was computing."""
        s, scene, parameters = self.steps, self.scene, self.parameters
        observer = self.observer()
        self.report_newton_steps()
        self.progress.start_loop(self.completed_steps, self.planned_steps())
        try:
            if scene.coupling and not s.monolithic:
                contraction = ContractionNorm(self.F, parameters.q, self.comm)
                run_fixed_stress(scene, parameters, self.materials, self.F, s.flow, s.second_pass, s.mechanics,
                                 contraction, self.output, observer, self.report, self.comm, self.grid,
                                 s.step_control)
            else:
                run_single_solve(scene, self.F, s.flow, s.mechanics, s.monolithic, observer, self.report,
                                 self.grid, s.step_control)
        except CouplingError as e:
            self.failure = str(e)  # names its step and the last increments
        except SolverError as e:
            self.failure = f"{self.step_being_computed()}: {e}"
            self.report.windows = self.completed_steps
        self.fields.contact = s.compute_contact()

    def planned_steps(self):
        """The mechanics steps (windows) of the run, for the progress: with
        coupling.q = "auto" those done and the rest at the last window's q."""
        q = self.report.window_q or self.parameters.q
        return self.report.windows + (self.grid.steps() - self.report.fine_steps + q - 1) // q

    def step_being_computed(self):
        """"step N (t = T)" of the step after the last completed one."""
        step = self.completed_steps + 1
        if not self.grid or not self.grid.t:
            return f"step {step}"
        k = min(self.report.fine_steps + self.parameters.q, len(self.grid.t) - 1)
        return f"step {step} (t = {self.grid.t[k]:g})"

    def stop_at_output_failure(self, e):
        """A file could not be written (a full disk): the run ends with what
        was finished, and the failure names the step it was writing."""
        self.failure = (f"after step {self.completed_steps}" if self.checkpointing else self.step_being_computed()) \
            + f": {e}"
        self.output_failed = True
        self.report.windows = self.completed_steps

    def write_summary(self):
        """summary.json: the scheme, sizes, counts, contraction measures,
        solvers, timings, contact and closed-form errors of the run, whatever
        its end (when the disk is full, as far as it can be written)."""
        if self.output is None:
            return
        scene, s, parameters, report, d = self.scene, self.steps, self.parameters, self.report, self.domain.dim
        dofs = {}
        if s.u is not None:
            dofs["displacement"] = global_size(s.V)
        if s.p is not None:
            dofs["pressure"] = global_size(s.p.function_space)
            dofs["flux"] = self.domain.mesh.topology.index_map(d - 1).size_global  # RT0: one per facet
        st = statistics(s)
        solvers, timings = solver_summaries(s, scene.solver.inexact_coupling)
        timings["assembly"] = s.assembly_time() + sum(x.assembly_time for x in st.values())
        timings["output"] = self.output.time
        c = scene.coupling
        summary = {
            "scene": scene.name,
            "scheme": c.scheme if c else ("flow-only" if s.flow else "mechanics-only"),
            "q": parameters.q,
            "L_choice": c.L_choice if c else "none",
            "acceleration": f"anderson, depth {c.depth}" if c and c.acceleration == "anderson" else "none",
            "L": parameters.L,
            "gamma": parameters.gamma,
            "dofs": dofs,
            "dt": scene.dt,
            "dt_growth": scene.growth,
            "time_scheme": scene.time_scheme,
            "steps": report.windows,
            "retries": report.retries,
            "fine_steps": report.fine_steps,
            "coupling_iterations": report.coupling_iterations,
            "max_iterations_per_step": report.max_iterations_per_step,
            "max_contraction_ratio": report.max_contraction_ratio,
            "mean_contraction_ratio": report.mean_contraction_ratio,
            "bound_violations": report.bound_violations,
            "resolved_ratios": report.ratios,
            "unresolved_ratios": report.unresolved_ratios,
            "max_coupled_residual": report.max_coupled_residual,
            "converged": not self.failure,
            "status": "failed" if self.failure else "interrupted" if self.signal else "completed",
            "last_completed_time": self.completed_time,
            "flow_solves": st["flow"].solves + st["flow_second_pass"].solves,  # both passes
            "mechanics_solves": st["mechanics"].solves,
            "monolithic_solves": st["monolithic"].solves,
            "newton_iterations": st["mechanics"].newton_iterations + st["monolithic"].newton_iterations,
            "linear_iterations": {"flow": st["flow"].linear_iterations + st["flow_second_pass"].linear_iterations,
                                  "mechanics": st["mechanics"].linear_iterations,
                                  "monolithic": st["monolithic"].linear_iterations},
            "solvers": solvers,
            "timings": timings,
            "wall_time_s": self.progress.elapsed(),
            "left_out": self.left_out,
            "warnings": self.warnings,
            "mpi_ranks": self.comm.size,
        }
        if c and c.q_auto:
            summary["q"], summary["window_steps"] = "auto", window_steps_json(c, report)
        if scene.adaptive:
            summary["adaptive"] = adaptive_json(scene.adaptive, report, self.grid)
        if self.domain.regions.names:
            summary["regions"] = regions_json(self.domain.regions, self.materials)
        if s.contact_pressure is not None:
            summary["contact"] = contact_json(self.fields.contact)
        if scene.reference and not self.failure and not self.signal:
            summary["errors"] = closed_form_errors(scene, parameters, self.F, self.domain, s.u, s.p, self.comm)
        if self.failure:
            summary["failure"] = self.failure
        try:
            self.output.summary(summary)
        except OutputError as e:
            if self.output_failed:
                self.failure += "; summary.json could not be written either"
            else:
                self.stop_at_output_failure(e)

    def exit_status(self):
        """RUN_OK; 128 + the signal of an interruption; RUN_NOT_CONVERGED after
        a failure (everything finished is written)."""
        root = is_rank0(self.comm)
        if self.signal:
            if root:
                print(f"biotcontact: interrupted (signal {self.signal}) after step {self.completed_steps}, "
                      f"t = {self.completed_time:g}: everything up to there is in {self.directory}",
                      file=sys.stderr, flush=True)
            return 128 + self.signal
        if self.output_failed:
            if root:
                checkpoint = f"; its last checkpoint is of step {self.saved}" if self.saved > 0 else ""
                print(f"biotcontact: error: {self.failure} (steps 1 to {self.completed_steps}, "
                      f"t <= {self.completed_time:g}, are in {self.directory}{checkpoint})", file=sys.stderr, flush=True)
            return RUN_OUTPUT_FAILED
        if self.failure:
            if root:
                print(f"biotcontact: error: {self.failure} (log: {self.directory}/iterations.csv)", file=sys.stderr,
                      flush=True)
            return RUN_NOT_CONVERGED
        if root:
            print(f"wrote {self.output.xdmf_path()} and {self.directory}/summary.json "
                  f"({self.progress.elapsed():f} s)", flush=True)
        return RUN_OK


def run(scene, directory, comm, fingerprint="", restart=False):
    """Runs `scene` into `directory`; returns RUN_OK, or RUN_NOT_CONVERGED
    after writing what was finished and the iteration log, or 128 + the
    signal after an interruption."""
    return Simulation(scene, directory, comm, fingerprint, restart).run()
