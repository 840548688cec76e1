"""coupling.fallback's monolithic scheme: the scheme that solves a step the
split failed at, beside the split's, on the same mesh, and what it tells
the run (cpp/coupling/fallback.h)."""
import dataclasses

from ..assembly.forms import Forms
from ..assembly.materials import make_materials
from ..assembly.parameters import derive_parameters, set_constants
from ..assembly.problem import Problem
from ..scene.input import CouplingScheme, Fallback
from .scheme import Scheme


class MonolithicFallback:
    """The monolithic scheme of a split run's scene, made at the split's
    first failed step: the scene with coupling.scheme = "monolithic" and
    what set-up derives from it, on the split's domain, with forms of its
    own (they hold the constants: each scheme sets its dt). The run moves
    the state between the two schemes (output/checkpoint.py,
    restore_run_state)."""

    def __init__(self, split):
        coupling = dataclasses.replace(split.scene.coupling, scheme=CouplingScheme.monolithic,
                                       fallback=Fallback.none)
        self.scene = dataclasses.replace(split.scene, coupling=coupling)
        forms = Forms(split.domain.mesh)
        materials = make_materials(self.scene, split.domain, forms)
        parameters = derive_parameters(self.scene)
        parameters.gamma = materials.gamma
        set_constants(forms, self.scene, parameters)
        self.problem = Problem(self.scene, split.domain, forms, materials, parameters)
        self.scheme = Scheme(self.problem)


@dataclasses.dataclass
class SolvedStep:
    """The split's failed step as the monolithic scheme solves it: its
    number, the time reached and the iterations of its steps."""
    step: int = 0
    t: float = 0.0
    iterations: int = 0


def fallback_observer(split, solved, end, write_flow):
    """The observer of the monolithic scheme's steps for the split's failed
    step `solved` ending at `end`, from the run's observer `split`: they
    fill `solved` and stop at or past `end`; their rows in iterations.csv
    carry the step's number, their retries (time.retry, which count their
    own fine steps) name the scheme; each fine step before `end` is written
    by `write_flow` (a multirate window's), the last left to the run with
    the mechanics."""
    def flow_state(t):
        if t < end:
            write_flow(t)

    def mechanics_state(t, _, iterations):
        solved.t = t
        solved.iterations += iterations
    return dataclasses.replace(split, flow_state=flow_state, mechanics_state=mechanics_state,
                               stop=lambda: solved.t >= end,  # time.adaptive's steps may pass it
                               retry=lambda message: split.retry(f"the monolithic scheme: {message}"),
                               record=lambda r: split.record(dataclasses.replace(r, step=solved.step)))
