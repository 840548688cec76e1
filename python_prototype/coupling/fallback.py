"""coupling.fallback's monolithic scheme: the scheme that solves a step the
single-rate split failed at, beside the split's, on the same mesh
(cpp/coupling/fallback.h)."""
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
