"""What every module shares about a scene's input (cpp/scene/input.h): bad
input raises SceneError, one line naming the file and the key; a choice is
one of a few named values, read into its enum once, when the scene is read
(schema.py the schema, section.py the reader).

Each enum's values are the names the scene gives them, in the order the
messages list them (C++ keeps that list apart, in Choices<E>)."""
import enum
import math


class SceneError(Exception):
    """Bad input: the message is one line naming the file and the key."""


def nonnegative_problem(v):
    """What is wrong with a value that must be >= 0: "is NaN", "is
    infinite" or "must be >= 0, got V" (six decimals, as C++'s
    std::to_string); empty when it is fine."""
    if math.isnan(v):
        return "is NaN"
    if math.isinf(v):
        return "is infinite"
    return "" if v >= 0 else f"must be >= 0, got {v:f}"


def point_text(x, d):
    """A point for a message: "(x, y)" or "(x, y, z)", each coordinate with
    six decimals as C++'s std::to_string prints it, so that both tracks
    refuse an input in the same words."""
    return "(" + ", ".join(f"{float(v):f}" for v in x[:d]) + ")"


def name_of(value):
    """The scene's name of a choice's value."""
    return value.value


class MeshType(enum.Enum):
    rectangle = "rectangle"
    box = "box"
    gmsh = "gmsh"


class CouplingScheme(enum.Enum):
    """The coupling scheme: "fixed-stress" (single rate), "multirate" (the
    paper's, as printed), "multirate-two-pass" (docs/multirate-two-pass.md: a
    second flow pass without L corrects the fine steps) or "monolithic"."""
    fixed_stress = "fixed-stress"
    multirate = "multirate"
    multirate_two_pass = "multirate-two-pass"
    monolithic = "monolithic"


class LChoice(enum.Enum):
    """The fixed-stress stabilisation L: alpha^2/lambda ("paper"),
    alpha^2/K_dr ("kdr"), half of that ("half-kdr"), or a number."""
    paper = "paper"
    kdr = "kdr"
    half_kdr = "half-kdr"
    number = "number"


class Acceleration(enum.Enum):
    """The acceleration of the split: none (the paper's iteration),
    Anderson's (coupling/anderson.py), or "auto": the paper's iteration,
    Anderson's in a window from where it stagnates (coupling/cycle.py)."""
    none = "none"
    anderson = "anderson"
    automatic = "auto"


class Fallback(enum.Enum):
    """coupling.fallback: what solves a step the split fails at (after
    time.retry's halvings): nothing (the run ends there) or the monolithic
    scheme, from the last completed step; the split goes on after it."""
    none = "none"
    monolithic = "monolithic"


class TimeScheme(enum.Enum):
    """time.scheme: the discrete time derivative (time/time_scheme.py)."""
    backward_euler = "backward-euler"
    bdf2 = "bdf2"


class SolverChoice(enum.Enum):
    """How a system is solved: a factorisation, a Krylov method, or chosen by
    size ("auto", solvers/solver.py choose_method)."""
    direct = "direct"
    iterative = "iterative"
    automatic = "auto"


class FaultFlow(enum.Enum):
    """fault.NAME.flow: what the fault is to the flow (issue 37): no obstacle
    ("transparent"), a barrier ("sealing"), held at its `pressure`, or a
    conduit with a pressure and a flow of its own (issue 39, docs/theory.md
    "Flow in a fault")."""
    transparent = "transparent"
    sealing = "sealing"
    pressure = "pressure"
    conduit = "conduit"


class ReferenceSolution(enum.Enum):
    """The closed form of [reference]."""
    terzaghi = "terzaghi"
    mandel = "mandel"
