"""The scheme of a run: the steps a scene needs (each scene allocates only
the physics it has) and the loop that drives them, the fixed-stress split
or one solve per step, chosen once from the scene (cpp/coupling/scheme.h)."""
from ..assembly.forms import Forms
from ..assembly.parameters import derive_parameters, set_constants
from ..contact.contact_state import ContactState
from ..scene.input import CouplingScheme
from ..steps.flow_step import FlowPass, FlowStep
from ..steps.mechanics_step import MechanicsStep
from ..steps.seismic_moments import SeismicMoments
from ..steps.monolithic_step import MonolithicStep
from .fixed_stress import SplitSteps, run_fixed_stress
from .single_solve import run_single_solve
from ..time.step_control import StepControl


class Scheme:
    """The steps of a run and the scheme that drives them; the fields output
    and diagnostics read, whichever step produced them.

    The split ("single-rate", "multirate", "multirate-two-pass") has a flow
    and a mechanics step (and the second pass's flow step); "monolithic" one
    coupled step; a scene with one physics its one step."""

    def __init__(self, problem):
        self.V = None  # displacement space (None without mechanics)
        self.u = self.p = self.contact_pressure = self.contact_active = self.contact_boundary = None
        # The pore pressure mechanics.pore_pressure gives (one-way coupling),
        # None otherwise: sigma_v's pressure where there is no flow.
        self.given_pressure = None
        self.step_control = None  # time.adaptive
        self._problem = problem
        self._steps = []
        self._flow = self._second_pass = self._mechanics = self._monolithic = None
        scene = problem.scene
        if scene.coupling and scene.coupling.scheme == CouplingScheme.monolithic:
            self._make_monolithic(problem)
        else:
            self._make_split(problem)
        if scene.adaptive:
            self.step_control = StepControl(scene, self.p.function_space if self.p else None, self.V)

    def run(self, run):
        """Drives the steps from the end of run.report.windows to the end
        time (a CouplingRun): the split's flow and mechanics steps
        (fixed_stress.py), or one solve per step of the one step, monolithic
        or a single physics' (single_solve.py)."""
        if self._problem.scene.coupling and self._monolithic is None:
            run_fixed_stress(self._problem, SplitSteps(self._flow, self._second_pass, self._mechanics), run)
        else:
            run_single_solve(self._problem, self._steps[0], run)

    # What output and diagnostics read, asked of the step that owns it: the
    # monolithic step, else the split's (or a single physics') flow or
    # mechanics step.

    def flux(self, out):
        """The flux into `out` (FlowStep.flux or MonolithicStep.flux; nothing
        without flow)."""
        if self._monolithic is not None:
            self._monolithic.flux(out)
        elif self._flow is not None:
            self._flow.flux(out)

    def fault_flow(self, t):
        """The conduit faults' cell fields at t (FlowStep.fault_flow or
        MonolithicStep.fault_flow; None without flow)."""
        if self._monolithic is not None:
            return self._monolithic.fault_flow(t)
        if self._flow is not None:
            return self._flow.fault_flow(t)
        return None

    def seismic_moments(self):
        """The faults' seismic moments step by step (MechanicsStep's or
        MonolithicStep's seismic_moments; none without mechanics)."""
        if self._monolithic is not None:
            return self._monolithic.seismic_moments()
        if self._mechanics is not None:
            return self._mechanics.seismic_moments()
        return SeismicMoments()

    def fault_volumes(self):
        """The conduit faults' volumes since the run's start
        (FlowStep.fault_volumes or MonolithicStep.fault_volumes; none without
        flow)."""
        if self._monolithic is not None:
            return self._monolithic.fault_volumes()
        if self._flow is not None:
            return self._flow.fault_volumes()
        return []

    def fault_intersections(self):
        """Where the conduit faults meet, and the rates through
        (FlowStep.fault_intersections or MonolithicStep.fault_intersections;
        none without conduit faults)."""
        if self._monolithic is not None:
            return self._monolithic.fault_intersections()
        if self._flow is not None:
            return self._flow.fault_intersections()
        return []

    def contact_state(self):
        """The contact's state (MechanicsStep.contact_state or
        MonolithicStep.contact_state; empty when the step has no contact)."""
        if self._monolithic is not None and self._monolithic.has_contact():
            return self._monolithic.contact_state()
        if self._mechanics is not None and self._mechanics.has_contact():
            return self._mechanics.contact_state()
        return ContactState()

    def start(self, state):
        """time.adaptive's scales from the state at t = 0, into the
        ControllerState `state` (nothing without it)."""
        if self.step_control:
            self.step_control.start(self.p.x.array if self.p else None, self.u.x.array if self.u else None,
                                    state.adaptive)

    def on_newton_step(self, told):
        """`told(system, iteration)` after each Newton step of a contact solve."""
        for step in self._steps:
            if step.system.has_contact():
                step.system.contact.on_newton_step(lambda iteration, name=step.name(): told(name, iteration))

    def steps(self):
        """The steps, in the order of summary.json."""
        return self._steps

    def history(self):
        """The time scheme's and time.adaptive's memory, by checkpoint name."""
        h = [entry for step in self._steps for entry in step.history()]
        return h + (self.step_control.history() if self.step_control else [])

    def assembly_time(self):
        """Assembly time of the steps' loads and matrices."""
        return sum(step.assembly_time for step in self._steps)

    def _make_monolithic(self, problem):
        """u, z and p in one system."""
        m = self._monolithic = MonolithicStep(problem)
        self._steps = [m]
        self.V, self.u, self.p = m.V, m.u, m.pressure
        self._take_contact_fields(m)

    def _make_split(self, problem):
        """The flow step and the mechanics step of the split, or the one a
        single physics has; "multirate-two-pass" adds the flow step without L."""
        scene, flow, second_pass, mechanics = problem.scene, None, None, None
        if scene.mechanics:
            self.V = problem.forms["V"]
        if scene.flow:
            flow = FlowStep(problem, self.V if scene.coupling else None)
            self.p = flow.pressure
            self._steps.append(flow)
        if scene.mechanics:
            mechanics = MechanicsStep(problem, self.V, self.p)
            if flow is not None and flow.fault_aperture:
                mechanics.load_fault_pressure(flow.fault_aperture, flow.fault_pressure)
                flow.read_fault_traction(mechanics)
            self.u, self.given_pressure = mechanics.u, mechanics.given_pressure
            self._take_contact_fields(mechanics)
            self._steps.append(mechanics)
        if scene.coupling and scene.coupling.scheme == CouplingScheme.multirate_two_pass:
            # The second pass is the flow step without the stabilisation L:
            # forms of its own, whose coefficient L is 0.
            unstabilised = Forms(problem.domain.mesh)
            set_constants(unstabilised, scene, derive_parameters(scene))
            materials = problem.materials.without_stabilisation(problem.forms, unstabilised)
            second_pass = FlowStep(problem.with_materials(materials, unstabilised), self.V, FlowPass.second)
            if second_pass.fault_aperture:
                second_pass.read_fault_traction(mechanics)
            self._steps.append(second_pass)
        self._flow, self._second_pass, self._mechanics = flow, second_pass, mechanics

    def _take_contact_fields(self, step):
        """The contact fields of a step that has them."""
        if not step.has_contact():
            return
        self.contact_pressure, self.contact_active = step.contact_pressure, step.contact_active
        self.contact_boundary = step.contact_boundary
