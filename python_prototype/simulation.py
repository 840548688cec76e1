"""A run of one scene (cpp/simulation.cpp), in the order of its story: set
up the problem (mesh, forms, materials), describe it, make the scheme and
its steps, open the output, start or restore, the time loop, the summary
and the exit status."""
import dataclasses
import math
import os

from .assembly.forms import Forms
from .assembly.materials import make_materials
from .assembly.parameters import derive_parameters, set_constants
from .assembly.problem import Problem
from .contact.contact_state import ContactState
from .coupling.contraction import relative
from .coupling.coupling import (ControllerState, CouplingError, CouplingReport, CouplingRun, IterationRecord,
                                WindowObserver)
from .coupling.fallback import MonolithicFallback, SolvedStep, fallback_observer
from .coupling.scheme import Scheme
from .diagnostics.closed_form import with_mandel_plate
from .diagnostics.description import Description, describe
from .diagnostics.reference_errors import reference_errors
from .domain.create_domain import create_domain
from .domain.working_ranks import working_ranks_line
from .domain.mesh_checks import check_expressions
from .output.checkpoint import (RunState, capture_checkpoint, read_checkpoint, restart_proposal, restore_checkpoint,
                                restore_run_state, write_checkpoint)
from .output.directory_lock import DirectoryLock
from .output.fields import OutputFields
from .output.interruption import interruption_signal
from .output.output import Output
from .output.progress import Progress, RunEnd
from .output.summary import RunOutcome, SummaryInput, run_summary
from .output.write_failure import OutputError
from .scene.input import Fallback
from .solvers.solver import SolverError
from .time.time_grid import time_grid


class Simulation:
    """One run of a scene, in the order of its story: set up the problem,
    describe it, make the scheme and its steps, open the output, start or
    restore, the time loop, the summary and the exit status."""

    def __init__(self, scene, directory, comm, fingerprint="", restart=False):
        # The scene as read, with a closed form's boundary values imposed.
        self.scene, self.directory = with_mandel_plate(scene), directory
        self.world = self.comm = comm  # the ranks started; those that work (domain/working_ranks.py)
        self.fingerprint, self.restart = fingerprint, restart
        # output.progress_interval (seconds between lines within a step)
        self.progress = Progress(comm, scene.progress_interval)
        self.domain = self.F = self.materials = self.parameters = self.problem = None
        self.description = Description()
        self.scheme = self.resumed = self.lock = self.output = self.fields = self.grid = None
        # The last completed step's checkpoint, with output.checkpoint_every
        # or coupling.fallback; coupling.fallback's monolithic scheme, from
        # the split's first failed step.
        self.completed = self.fallback = None
        self.report, self.state = CouplingReport(), ControllerState()
        self.end = RunEnd()          # the steps completed and saved so far; why the run stopped
        self.checkpointing = False   # writing the checkpoint of the last completed step

    def run(self):
        """The story of a run; the files are closed and the directory's lock
        released however it ends."""
        try:
            self.set_up()
            if self.domain is None:
                return 0  # this rank waits; main takes rank 0's status
            self.scheme = Scheme(self.problem)
            try:
                self.open_output()
                self.start_or_restore()
                self.time_loop()
            except OutputError as e:
                self.stop_at_output_failure(e)
            except SolverError as e:  # the initial equilibrium (start_or_restore)
                self.end.failure = str(e)
            self.write_summary()
        finally:
            self.close_output()
        return self.exit_status()

    def set_up(self):
        """The problem: the mesh and its tags, the forms on it, the materials
        of its cells, the derived parameters and the constants of the forms;
        then what the scene leaves out, and warnings where the method is
        known to degrade (diagnostics/description.py)."""
        self.domain = create_domain(self.scene, self.world)
        if self.domain is None:
            return
        ranks = working_ranks_line(self.world, self.domain.mesh, self.scene.solver.cells_per_rank)
        self.comm = self.domain.mesh.comm
        check_expressions(self.scene, self.domain, self.comm)
        self.F = Forms(self.domain.mesh)
        self.materials = make_materials(self.scene, self.domain, self.F)
        self.parameters = derive_parameters(self.scene)
        self.parameters.gamma = self.materials.gamma  # the largest of any cell
        set_constants(self.F, self.scene, self.parameters)
        self.problem = Problem(self.scene, self.domain, self.F, self.materials, self.parameters)
        self.description = describe(self.problem)
        if ranks:
            self.description.lines.append(ranks)
        for line in self.description.lines:
            self.progress.say(line)

    def run_state(self):
        """What a checkpoint keeps of the run and a restart restores."""
        return RunState(self.scheme, self.domain.mesh, self.report, self.state, self.grid)

    def open_output(self):
        """The time grid, the checkpoint a restart goes on from (loaded into
        the steps), the output files (created, or those of the checkpoint's
        run) and the fields written into them."""
        # The lock first: nothing in the directory is read, created or
        # truncated while another run holds it. A restart of a directory that
        # does not exist is refused by read_checkpoint, without creating it.
        # Rank 0's view decides for all (ranks may see a file system
        # differently), so that every rank meets the same collectives next.
        if self.comm.bcast(not self.restart or os.path.isdir(self.directory), root=0):
            self.lock = DirectoryLock(self.comm, self.directory)
        self.grid = time_grid(self.scene)  # a retry (time.retry) halves some of its steps
        if self.restart:
            # Loaded before the files are opened: a checkpoint that does not
            # match is refused with the files as they were.
            self.resumed = read_checkpoint(self.comm, self.directory, self.fingerprint)
            restore_checkpoint(self.resumed, self.run_state(), self.comm, self.directory)
        self.output = Output(self.comm, self.directory, self.domain.mesh, self.scene.write_xdmf,
                             self.resumed.output if self.resumed else None)
        self.fields = OutputFields(self.problem, self.scheme, self.output,
                                   self.resumed.time if self.resumed else None)

    def close_output(self):
        """The files closed and the directory's lock released."""
        if self.fields is not None:
            self.fields.close()
        if self.output is not None:
            self.output.close()
        if self.lock is not None:
            self.lock.release()

    def equilibrate(self):
        """mechanics.initial_equilibrium: the solve at t = 0, a row of
        iterations.csv at step 0 for each solve (its contact solve's Newton
        steps)."""
        i = 0
        try:
            for step in self.scheme.steps():
                for s in step.equilibrate():
                    i += 1
                    self.output.iteration(IterationRecord(0, 0.0, i, math.nan, math.nan, math.nan, relative(s.dp, s.p),
                                                          relative(s.du, s.u), s.active_nodes, math.nan, math.nan,
                                                          s.newton_steps))
        except SolverError as e:
            raise SolverError(f"the initial equilibrium (t = 0): {e}") from None

    def start_or_restore(self):
        """The initial state, written at t = 0, or the checkpoint's step and time."""
        s = self.scheme
        if self.resumed:
            self.end.saved = self.end.completed_steps = self.resumed.steps
            self.end.completed_time = self.resumed.time
            if s.u is not None:
                self.fields.contact = s.contact_state()
            self.progress.say(f"restarted from the checkpoint at step {self.end.completed_steps}, "
                              f"t = {self.end.completed_time:f}")
            return
        if self.scene.mechanics and self.scene.mechanics.initial_equilibrium:
            self.equilibrate()
        self.fields.write_flow(0.0)
        if s.u is not None:
            self.fields.write_mechanics(0.0)
        if s.contact_boundary is not None:
            self.output.write(s.contact_boundary, 0.0)  # once: every later time repeats it
        s.start(self.state)

    def stop(self):
        """After each completed (and written) step: a checkpoint every
        checkpoint_every steps and at an interruption; then whether to stop.
        The last completed step is kept in memory too: a step that fails
        writes it (save_on_failure)."""
        end, every = self.end, self.scene.checkpoint_every
        if every > 0 or self.falls_back():
            self.completed = capture_checkpoint(self.run_state(), end.completed_steps, end.completed_time,
                                                self.output.position())
        if every > 0 and end.completed_steps % every == 0:
            self.save_completed()
        end.signal = interruption_signal(self.comm)
        if end.signal and every > 0 and end.saved != end.completed_steps:
            self.save_completed()
        return end.signal != 0

    def save_completed(self):
        """Writes the checkpoint of the last completed step."""
        self.checkpointing = True
        write_checkpoint(self.comm, self.directory, self.fingerprint, self.completed)
        self.checkpointing = False
        self.end.saved = self.completed.steps

    def save_on_failure(self):
        """A step failed: the checkpoint of the last completed one, where the
        run writes checkpoints and has not written it, so that nothing it
        finished is lost and a restart goes on from there
        (restart_proposal)."""
        if self.completed is None or self.scene.checkpoint_every == 0:
            return
        steps = self.completed.steps
        try:
            if self.end.saved != steps:
                self.save_completed()
            self.end.failure += (f"; step {steps} is in the checkpoint (--restart {self.directory}"
                                 f"{restart_proposal(self.end.failure, self.scene)} goes on from it)")
        except OutputError as e:
            self.checkpointing = False
            self.end.failure += f"; the checkpoint of step {steps} could not be written: {e}"

    def observer(self):
        """What the coupling schemes tell the run: write each step, print the
        progress, log each iteration, checkpoint, stop at an interruption."""
        def flow_state(t):
            if self.scene.is_output_time(t):
                self.fields.write_flow(t)

        def mechanics_state(t, step, iterations):
            if self.scheme.u is not None and self.scene.is_output_time(t):
                self.fields.write_mechanics(t)
            elif self.scheme.u is not None:
                self.fields.read_contact()
            self.end.completed_steps, self.end.completed_time = step, t
            self.progress.step(step, self.planned_steps(), t, iterations,
                               self.fields.contact.active_nodes)
        return WindowObserver(flow_state=flow_state, mechanics_state=mechanics_state, stop=self.stop,
                              retry=self.progress.say, note=self.progress.say, iteration=self.progress.iteration,
                              record=self.output.iteration)

    def time_loop(self):
        """The steps from t = 0 (or the checkpoint) to the end, driven by the
        scheme. A failure ends the loop with what was finished written; it
        names the step it was computing. With coupling.fallback the
        monolithic scheme solves a step the split failed at, and the split
        goes on from it."""
        run = CouplingRun(self.grid, self.scheme.step_control, self.observer(), self.report, self.state)
        self.report_newton_steps(self.scheme)
        self.progress.start_loop(self.end.completed_steps, self.planned_steps())
        if self.falls_back():
            self.completed = capture_checkpoint(self.run_state(), self.end.completed_steps, self.end.completed_time,
                                                self.output.position())
        while True:
            try:
                self.scheme.run(run)
                break
            except CouplingError as e:
                self.end.failure = str(e)  # names its step and the last increments
            except SolverError as e:
                self.end.failure = f"{self.step_being_computed()}: {e}"
                self.report.windows = self.end.completed_steps
            if not self.fall_back():
                break
        if self.end.failure:
            self.save_on_failure()
            self.fields.contact = self.scheme.contact_state()  # at the failure

    def falls_back(self):
        """Whether the scene has coupling.fallback = "monolithic"."""
        return self.scene.coupling is not None and self.scene.coupling.fallback == Fallback.monolithic

    def fall_back(self):
        """coupling.fallback: after the split failed at a step (end.failure),
        the monolithic scheme solves it from the last completed step, and the
        split takes its state (restore_run_state, as a restart with another
        coupling.scheme); the step is written and counted (fallback_steps).
        Returns whether the split goes on: not when the run has no fallback,
        the monolithic solve fails too (the failure says both) or the run is
        interrupted."""
        if not self.falls_back() or self.completed is None:
            return False
        self.progress.say(f"{self.end.failure}; the monolithic scheme solves the step (coupling.fallback)")
        try:
            solved = self.solve_by_fallback()
        except (CouplingError, SolverError) as e:
            self.end.failure += f"; the monolithic scheme failed there too (coupling.fallback): {e}"
            restore_run_state(self.completed, self.run_state(), self.comm, self.directory)
            return False
        self.end.failure = ""
        self.report.fallback_steps += 1
        # The step's fields are the monolithic scheme's, which solved it.
        o = self.observer()
        self.fields.read_from(self.fallback.scheme)
        o.flow_state(solved.t)
        o.mechanics_state(solved.t, solved.step, solved.iterations)
        self.fields.read_from(self.scheme)
        return not o.stop()

    def report_newton_steps(self, scheme):
        """A contact solve of `scheme` longer than the interval (a large
        monolithic step) prints its Newton steps as it goes, like the
        coupling iterations of the split."""
        scheme.on_newton_step(
            lambda system, iteration: self.progress.newton_step(self.end.completed_steps + 1, system, iteration))

    def solve_by_fallback(self):
        """The monolithic scheme's steps from the last completed one to the
        end of the split's failed step, its state then the split's. A
        multirate window's q fine steps are q monolithic steps, each a
        window of one fine step for the history the split goes on from
        (WindowHistory.start); their rows in iterations.csv and the step in
        the progress are the window's (fallback_observer). Stops at the
        window's end time: a retry of the monolithic scheme halves steps
        within it."""
        if self.fallback is None:
            self.fallback = MonolithicFallback(self.problem)
            self.report_newton_steps(self.fallback.scheme)
        m = self.fallback.scheme
        monolithic = RunState(m, self.domain.mesh, self.report, self.state, self.grid)
        restore_run_state(self.completed, monolithic, self.comm, self.directory)
        end = self.grid.t[min(self.report.fine_steps + self.parameters.q, len(self.grid.t) - 1)]
        solved = SolvedStep(self.report.windows + 1)
        self.report.windows = self.report.fine_steps  # the monolithic scheme's steps are fine steps
        split = self.observer()

        def write_flow(t):
            self.fields.read_from(m)
            split.flow_state(t)
            self.fields.read_from(self.scheme)
        o = fallback_observer(split, solved, end, write_flow)
        m.run(CouplingRun(self.grid, m.step_control, o, self.report, self.state))
        self.report.windows = solved.step
        self.state.q_limit = 1  # coupling.q = "auto": the next window starts short, as after a contact change
        c = capture_checkpoint(monolithic, solved.step, solved.t, self.output.position())
        # With backward Euler the monolithic scheme keeps no displacement one
        # step before; q = "auto" reads it: the start of its one fine step.
        c.fields.setdefault("displacement_before", self.completed.fields["displacement"])
        restore_run_state(c, self.run_state(), self.comm, self.directory)
        return solved

    def planned_steps(self):
        """The mechanics steps (windows) of the run, for the progress: with
        coupling.q = "auto" those done and the rest at the last window's q."""
        q_auto = self.scene.coupling is not None and self.scene.coupling.q_auto
        q = self.state.window_q if q_auto and self.state.window_q else self.parameters.q
        return self.report.windows + (self.grid.steps() - self.report.fine_steps + q - 1) // q

    def step_being_computed(self):
        """"step N (t = T)" of the step after the last completed one."""
        step = self.end.completed_steps + 1
        if not self.grid or not self.grid.t:
            return f"step {step}"
        k = min(self.report.fine_steps + self.parameters.q, len(self.grid.t) - 1)
        return f"step {step} (t = {self.grid.t[k]:g})"

    def stop_at_output_failure(self, e):
        """A file could not be written (a full disk): the run ends with what
        was finished, and the failure names the step it was writing."""
        end = self.end
        # solution.xdmf, or fault.xdmf after it
        when = ("opening the output" if self.fields is None else f"after step {end.completed_steps}"
                if self.checkpointing else self.step_being_computed())
        end.failure = f"{when}: {e}"
        end.output_failed = True
        self.report.windows = end.completed_steps

    def write_summary(self):
        """summary.json (output/summary.py), whatever the run's end (when the
        disk is full, as far as it can be written)."""
        if self.output is None:
            return
        # no fields where the output files could not be made
        contact = self.fields.contact if self.fields is not None else ContactState()
        summary_input = SummaryInput(self.problem, self.scheme, self.report, self.grid, contact,
                                     fallback=self.fallback.scheme if self.fallback is not None else None)
        end = self.end
        if self.scene.reference and not end.failure and not end.signal:
            summary_input.errors = reference_errors(self.problem, self.scheme.u, self.scheme.p)
        outcome = RunOutcome(end.failure, end.signal, end.completed_time, self.description.left_out,
                             self.description.warnings, self.progress.elapsed(), self.output.time, self.world.size,
                             self.comm.size)
        try:
            self.output.summary(run_summary(summary_input, outcome))
        except OutputError as e:
            if end.output_failed:
                end.failure += "; summary.json could not be written either"
            else:
                self.stop_at_output_failure(e)

    def exit_status(self):
        """The last line and the exit status (output/progress.py)."""
        return self.progress.finish(self.end, self.directory, self.output.xdmf_path() if self.output else "")

def run(scene, directory, comm, fingerprint="", restart=False):
    """Runs `scene` into `directory`; returns RUN_OK, or RUN_NOT_CONVERGED
    after writing what was finished and the iteration log, RUN_OUTPUT_FAILED
    when a file could not be written (a full disk), or 128 + the signal after
    an interruption (output/progress.py)."""
    return Simulation(scene, directory, comm, fingerprint, restart).run()
