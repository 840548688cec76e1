"""The readers of a scene's physics (cpp/scene/physics_input.h): [mechanics],
[flow], [coupling] and the material regions [region.NAME], which replace
some of their values. Mirrors cpp/scene/physics_input.cpp key by key."""
import math

from .expression import Expression
from .input import Acceleration, CouplingScheme, Fallback, LChoice, MeshType
from .schema import CouplingSpec, FlowSpec, MechanicsSpec, RegionSpec
from .section import Section


def positive(s, key, value):
    """Refuses the value of `key` unless it is a positive finite number."""
    if not (value > 0) or not math.isfinite(value):
        s.fail(key, "must be a positive finite number")


def _read_given_pore_pressure(s, m):
    """mechanics.pore_pressure and its Biot coefficient mechanics.alpha: a
    pore pressure given as an expression loads the skeleton (one-way
    coupling); whether the scene may have one is read_physics's to say."""
    m.pore_pressure = s.expression("pore_pressure")
    if m.pore_pressure is not None and not s.has("alpha"):
        s.fail("alpha", "missing (the Biot coefficient of mechanics.pore_pressure)")
    if m.pore_pressure is None and s.has("alpha"):
        s.fail("alpha", "needs mechanics.pore_pressure (a coupled scene gives coupling.alpha)")
    m.alpha = s.number("alpha", 0.0)
    if m.pore_pressure is not None and not 0 < m.alpha <= 1:
        s.fail("alpha", "the Biot coefficient must lie in (0, 1]")


def _read_mechanics(s, d):
    m = MechanicsSpec()
    e_nu = s.has("E") or s.has("nu")
    lame = s.has("G") or s.has("lambda")
    if e_nu and lame:
        s.fail("E", "give either E and nu, or G and lambda, not both")
    if not e_nu and not lame:
        s.fail("E", "missing (give E and nu, or G and lambda)")
    if e_nu:
        E, nu = s.number("E"), s.number("nu")
        positive(s, "E", E)
        if not (-1.0 < nu < 0.5):
            s.fail("nu", "must lie in (-1, 0.5); nu >= 0.5 is an incompressible skeleton")
        m.G = E / (2 * (1 + nu))
        m.lmbda = E * nu / ((1 + nu) * (1 - 2 * nu))
    else:
        m.G, m.lmbda = s.number("G"), s.number("lambda")
        positive(s, "G", m.G)
        if not math.isfinite(m.lmbda) or m.lmbda + 2 * m.G / d <= 0:
            s.fail("lambda", "must be finite with K_dr = lambda + 2G/d > 0")
    if s.has("body_force"):
        m.body_force = s.expression_vector("body_force", d)
    m.initial_equilibrium = s.boolean("initial_equilibrium", False)
    _read_given_pore_pressure(s, m)
    s.finish()
    return m


def _spd(K, d):
    """Symmetric with positive leading minors."""
    sym = all(abs(K[i * d + j] - K[j * d + i]) <= 1e-12 * abs(K[i * d + i]) for i in range(d) for j in range(d))
    m1, m2 = K[0], K[0] * K[d + 1] - K[1] * K[d]
    m3 = 1.0
    if d == 3:
        m3 = (K[0] * (K[4] * K[8] - K[5] * K[7]) - K[1] * (K[3] * K[8] - K[5] * K[6])
              + K[2] * (K[3] * K[7] - K[4] * K[6]))
    return sym and m1 > 0 and m2 > 0 and m3 > 0


def _read_flow(s, d):
    f = FlowSpec()
    f.M = s.number("M", math.inf)
    if not (f.M > 0):
        s.fail("M", "must be positive (inf for incompressible grains)")
    f.c_f = s.number("c_f", 0.0)
    if not (f.c_f >= 0) or not math.isfinite(f.c_f):
        s.fail("c_f", "must be >= 0")
    f.phi0 = s.number("phi0", 0.0)
    if not (0 <= f.phi0 <= 1):
        s.fail("phi0", "must lie in [0, 1]")
    f.mu_f = s.number("mu_f")
    positive(s, "mu_f", f.mu_f)

    k = s.node("permeability")
    if k is None:
        s.fail("permeability", "missing")
    if isinstance(k, list):
        K = []
        for row in k:
            if not isinstance(row, list) or len(row) != d:
                s.fail("permeability", f"a tensor must be {d} rows of {d} numbers")
            for e in row:
                if not Section.is_number(e):
                    s.fail("permeability", "tensor entries must be numbers")
                K.append(float(e))
        if len(K) != d * d:
            s.fail("permeability", f"a tensor must have {d} rows")
        if not _spd(K, d):
            s.fail("permeability", "the tensor must be symmetric positive definite")
        f.permeability_tensor = K
    else:
        f.permeability = s.to_expression(k, "permeability")
        if f.permeability.is_constant:
            positive(s, "permeability", f.permeability(0, 0, 0, 0))
        if f.permeability.depends_on_time:
            s.fail("permeability", "must not depend on t")

    if s.has("gravity") != s.has("rho_f"):
        s.fail("rho_f" if s.has("gravity") else "gravity", "gravity needs both rho_f and gravity")
    if s.has("gravity"):
        f.rho_f = s.number("rho_f")
        positive(s, "rho_f", f.rho_f)
        f.gravity = s.number_vector("gravity", d)
    f.source = s.expression("source")
    f.initial_pressure = s.expression("initial_pressure") or Expression(0.0)
    if f.initial_pressure.depends_on_time:
        s.fail("initial_pressure", "must not depend on t")
    s.finish()
    return f


def _read_window_steps(s, c):
    """coupling.q: a positive integer, or "auto" (window_control.py) with
    the largest q (q_max) and the tolerance of the predicted relative change
    of the displacement over a window (q_tolerance)."""
    c.q_auto = s.node("q") == "auto"
    c.q = 1 if c.q_auto else s.integer("q", 1)
    if c.q < 1:
        s.fail("q", 'must be a positive integer or "auto"')
    if not c.multirate() and (c.q != 1 or c.q_auto):
        s.fail("q", ('q = "auto"' if c.q_auto else "q > 1") + ' needs scheme = "multirate" or "multirate-two-pass"')
    if not c.q_auto:
        for key in ("q_max", "q_tolerance"):
            if s.has(key):
                s.fail(key, 'needs q = "auto"')
        return
    c.q_max = s.integer("q_max", 16)
    if not 1 <= c.q_max <= 1024:
        s.fail("q_max", "must be an integer from 1 to 1024")
    c.q_tolerance = s.number("q_tolerance", 1e-2)
    if not 0 < c.q_tolerance < 1:
        s.fail("q_tolerance", "must lie in (0, 1)")


def _read_coupling(s, mech, flow):
    c = CouplingSpec()
    c.alpha = s.number("alpha")
    if not (0 <= c.alpha <= 1):
        s.fail("alpha", "the Biot coefficient must lie in [0, 1]")
    c.scheme = s.choice("scheme", CouplingScheme, CouplingScheme.fixed_stress)
    # The second pass is a flow step without L: with S = 0 its matrix has a
    # zero pressure block, singular wherever no pressure is prescribed.
    if c.scheme == CouplingScheme.multirate_two_pass and not flow.storage() > 0:
        s.fail("scheme", '"multirate-two-pass" needs a storage coefficient S = 1/M + c_f phi0 > 0')
    _read_window_steps(s, c)

    L = s.node("L")
    if L is None:
        c.L_choice = LChoice.paper
    elif Section.is_number(L):
        c.L_choice, c.L_number = LChoice.number, float(L)
        if not (c.L_number >= 0) or not math.isfinite(c.L_number):
            s.fail("L", "must be >= 0")
    elif isinstance(L, str) and L in ("paper", "kdr", "half-kdr"):
        c.L_choice = LChoice(L)
    else:
        s.fail("L", 'must be "paper", "kdr", "half-kdr" or a number')
    if c.L_choice == LChoice.paper and not (mech.lmbda > 0):
        s.fail("L", '"paper" (alpha^2/lambda) needs lambda > 0; use "kdr"')

    c.tolerance = s.number("tolerance", 1e-8)
    if not (0 < c.tolerance < 1):
        s.fail("tolerance", "must lie in (0, 1)")
    c.max_iterations = s.integer("max_iterations", 100)
    if c.max_iterations < 1:
        s.fail("max_iterations", "must be a positive integer")
    c.acceleration = s.choice("acceleration", Acceleration, Acceleration.automatic)
    if c.acceleration == Acceleration.anderson and c.scheme == CouplingScheme.monolithic:
        s.fail("acceleration", "accelerates the split; the monolithic scheme has no coupling iteration")
    c.depth = s.integer("depth", 8)
    if not 1 <= c.depth <= 50:
        s.fail("depth", "must be an integer from 1 to 50")
    c.fallback = s.choice("fallback", Fallback, Fallback.none)
    if c.fallback == Fallback.monolithic and c.scheme == CouplingScheme.monolithic:
        s.fail("fallback", "takes over a step the split fails at; the monolithic scheme has no split")
    c.pin_cycles = s.boolean("pin_cycles", True)
    s.finish()
    return c


def read_physics(top, scene):
    """[mechanics], [flow] and, when both are there, [coupling]."""
    d = scene.mesh.dimension
    if top.has("mechanics"):
        scene.mechanics = _read_mechanics(top.section("mechanics", True), d)
    if top.has("flow"):
        scene.flow = _read_flow(top.section("flow", True), d)
    if not scene.mechanics and not scene.flow:
        top.fail("mechanics", "a scene needs a [mechanics] or a [flow] table (or both)")
    if scene.flow and scene.mechanics and scene.mechanics.pore_pressure is not None:
        top.fail("mechanics.pore_pressure", "a given pore pressure is for a scene without [flow] (here the flow "
                 "computes it)")
    if scene.mechanics and scene.flow:
        scene.coupling = _read_coupling(top.section("coupling", True), scene.mechanics, scene.flow)
    elif top.has("coupling"):
        top.fail("coupling", "only a scene with both [mechanics] and [flow] is coupled")


_MECHANICS_KEYS = ("E", "nu", "G", "lambda", "body_force")
_FLOW_KEYS = ("M", "c_f", "phi0", "permeability")


def _region_physics(root, physics, region, keys):
    """A copy of the scene's table `physics` with the region's values of
    `keys` in place of its own; giving one of a pair of moduli drops the
    other pair from the copy (E, nu replace G, lambda)."""
    merged = dict(root[physics])
    if any(k in region for k in ("E", "nu")):
        merged.pop("G", None), merged.pop("lambda", None)
    if any(k in region for k in ("G", "lambda")):
        merged.pop("E", None), merged.pop("nu", None)
    merged.update({k: region[k] for k in keys if k in region})
    return merged


def _check_region_keys(s, scene):
    """Each key of a region is a material value of a physics the scene has."""
    for key in s.keys():
        mechanics, flow = key in _MECHANICS_KEYS, key in _FLOW_KEYS
        if key not in ("where", "alpha") and not mechanics and not flow:
            s.fail(key, "unknown key (a region may set where, E, nu, G, lambda, body_force, alpha, M, c_f, phi0, "
                   "permeability)")
        if (mechanics and not scene.mechanics) or (flow and not scene.flow) or (key == "alpha" and not scene.coupling):
            s.fail(key, "the scene has no [" + ("mechanics" if mechanics else "flow" if flow else "coupling")
                   + "] whose value a region could replace")
        s.node(key)


def read_regions(regions, root, scene):
    """[region.NAME] (cpp/scene/physics_input.h): each region's physics
    are read by the readers of the scene's own tables, so errors name
    region.NAME.KEY; which cells it holds is settled with the domain."""
    d = scene.mesh.dimension
    for name in regions.keys():
        s = regions.section(name, True)
        _check_region_keys(s, scene)
        r = RegionSpec(where=s.expression("where"), body_force=s.has("body_force"))
        if r.where is not None and (r.where.depends_on_time or r.where.is_constant):
            s.fail("where", "must be an expression of x, y, z (the cell midpoints it selects)")
        if scene.mesh.type != MeshType.gmsh and r.where is None:
            s.fail("where", "missing (on a built-in mesh a region is the cells whose midpoint satisfies where)")
        if scene.mechanics:
            merged = _region_physics(root, "mechanics", s.table, _MECHANICS_KEYS)
            r.mechanics = _read_mechanics(regions.derived(merged, name), d)
        if scene.flow:
            merged = _region_physics(root, "flow", s.table, _FLOW_KEYS)
            r.flow = _read_flow(regions.derived(merged, name), d)
        if scene.coupling:
            r.alpha = s.number("alpha", scene.coupling.alpha)
            if not (0 <= r.alpha <= 1):
                s.fail("alpha", "the Biot coefficient must lie in [0, 1]")
            if scene.coupling.L_choice == LChoice.paper and not r.mechanics.lmbda > 0:
                s.fail("lambda", 'coupling.L = "paper" (alpha^2/lambda) needs lambda > 0; use "kdr"')
        elif r.mechanics:
            r.alpha = r.mechanics.alpha  # mechanics.pore_pressure's, which a region does not replace
        s.finish()
        scene.regions[name] = r
    regions.finish()
