"""Derived parameters of a scene and the constants and coefficients they set
in the forms (cpp/assembly/parameters.cpp)."""
from dataclasses import dataclass

import numpy as np

from ..scene.input import LChoice
from .node_coordinates import node_coordinates, on_mesh_nodes


@dataclass
class Parameters:
    """Derived parameters of a scene (alg. "Parameters")."""
    d: int = 2
    G: float = 0.0
    lmbda: float = 0.0
    alpha: float = 0.0
    storage: float = 0.0  # S = 1/M + c_f phi0
    K_dr: float = 0.0     # lambda + 2G/d
    L: float = 0.0        # fixed-stress stabilisation used
    gamma: float = 0.0    # Theorems 1 and 2: alpha^2/(alpha^2 + lambda S)
    q: int = 1
    dt: float = 0.0       # fine (flow) step


def _material_parameters(scene, mechanics, flow, alpha):
    """The parameters of one material: its moduli, storage, alpha
    (coupling.alpha, or mechanics.alpha of a given pore pressure) and the L
    that coupling.L chooses for them."""
    parameters = Parameters(d=scene.mesh.dimension, dt=scene.dt)
    if mechanics:
        parameters.G, parameters.lmbda = mechanics.G, mechanics.lmbda
        parameters.K_dr = parameters.lmbda + 2 * parameters.G / parameters.d
    if flow:
        parameters.storage = flow.storage()
    parameters.alpha = alpha
    if scene.coupling:
        c = scene.coupling
        parameters.q = c.q
        a2 = parameters.alpha * parameters.alpha
        parameters.L = {LChoice.paper: lambda: a2 / parameters.lmbda, LChoice.kdr: lambda: a2 / parameters.K_dr,
                        LChoice.half_kdr: lambda: a2 / (2 * parameters.K_dr)}.get(c.L_choice, lambda: c.L_number)()
        parameters.gamma = a2 / (a2 + parameters.lmbda * parameters.storage) if a2 > 0 else 0.0
    return parameters


def derive_parameters(scene, region=None):
    """The parameters of the scene's top-level material, or of a region's."""
    if region is None:
        alpha = scene.coupling.alpha if scene.coupling else scene.mechanics.alpha if scene.mechanics else 0.0
        return _material_parameters(scene, scene.mechanics, scene.flow, alpha)
    return _material_parameters(scene, region.mechanics, region.flow, region.alpha)


def set_constants(F, scene, parameters):
    """The constants of forms/biot.py from the parameters (unused ones stay 0)."""
    for name in ("dt", "q"):
        F[name].value = getattr(parameters, name)
    F["ones"].value = np.ones(parameters.d)
    if scene.flow and scene.flow.gravity:
        F["rho_f"].value = scene.flow.rho_f
        F["gravity"].value = np.array(scene.flow.gravity)


def _set_constant(F, name, value):
    """Sets a scalar constant ("dt" and "q" change between steps); returns
    whether it changed."""
    if F[name].value == value:
        return False
    F[name].value = value
    return True


def set_time_step(F, dt):
    """Sets the constant "dt" (it changes during a run with time.growth,
    time.adaptive and retries); returns whether it changed."""
    return _set_constant(F, "dt", dt)


def set_window_steps(F, q):
    """Sets the constant "q" (the fine steps of the current window; it
    changes between windows with coupling.q = "auto"); returns whether it
    changed."""
    return _set_constant(F, "q", q)


def interpolate(f, components, t):
    """Interpolates one expression per component (at time t) into f; on a
    P1 space at the mesh's own nodes (node_coordinates.py: sqrt(x) is
    defined at x = 0)."""
    V = f.function_space
    if on_mesh_nodes(V):
        if V.dofmap.index_map_bs != len(components):
            raise RuntimeError("interpolate: one expression per component of the space")
        x = node_coordinates(V).T
        f.x.array[:] = np.column_stack([c.at(x, t) * np.ones(x.shape[1]) for c in components]).ravel()
        return
    if len(components) == 1:
        f.interpolate(lambda x: components[0].at(x, t))
    else:
        f.interpolate(lambda x: np.vstack([c.at(x, t) for c in components]))


def resistivity(flow, d, x):
    """mu_f K^-1 at the columns of x (d*d rows): K from a scalar expression,
    or a constant tensor; and the columns where the expression is not positive."""
    v = np.zeros((d * d, x.shape[1]))
    if flow.permeability is not None:
        k = np.broadcast_to(np.asarray(flow.permeability.at(x, 0.0), dtype=float), (x.shape[1],))
        bad = np.flatnonzero(~((k > 0) & np.isfinite(k)))
        for i in range(d):
            v[i * d + i] = flow.mu_f / np.where(k > 0, k, 1.0)
        return v, bad
    K = np.array(flow.permeability_tensor).reshape(d, d)
    v[:] = (flow.mu_f * np.linalg.inv(K)).reshape(-1, 1)
    return v, np.zeros(0, dtype=int)
