"""How a conduit fault's aperture answers its pressure
(cpp/assembly/fault_compliance.h): the closure of a closed fault
(Barton-Bandis), the opening of an open patch (Sneddon), the patches of
open cells; their compliances are the fault's fixed-stress term L_f
(docs/theory.md "Flow in a fault")."""
import numpy as np


def softest_modulus(scene):
    """The smallest plane-strain modulus E' = E/(1 - nu^2) of the scene's
    materials (the softest rock)."""
    def modulus(m):  # E' = 4 G (lambda + G)/(lambda + 2 G)
        return 4 * m.G * (m.lmbda + m.G) / (m.lmbda + 2 * m.G)
    return min([modulus(scene.mechanics)] + [modulus(r.mechanics) for r in scene.regions.values() if r.mechanics])


def patch_compliance(size, modulus, dim):
    """The mean opening per unit pressure of an open patch of measure `size`
    (its length in 2D, its area in 3D) in an infinite body of plane-strain
    modulus E': Sneddon's pi a/E' for a 2D crack of half-length a = size/2,
    16 a/(3 pi E') for a penny of radius a (area pi a^2) in 3D; the fault's
    fixed-stress L_f of the patch's cells."""
    return np.pi * (size / 2) / modulus if dim == 2 else 16 * np.sqrt(size / np.pi) / (3 * np.pi * modulus)


def closure_aperture(closure, s_n):
    """Barton-Bandis: the closure's share of a closed fault's hydraulic
    aperture at the effective normal stress s_n (>= 0 pressing; 0 below),
    V_m - V_m s_n/(K_ni V_m + s_n): V_m at s_n = 0, falling to 0 as s_n
    grows."""
    # V_m - V_m s/(K_ni V_m + s) written without the cancellation at large s.
    stiffness = closure.K_ni * closure.V_m
    return closure.V_m * stiffness / (stiffness + np.maximum(s_n, 0.0))


def closure_compliance(closure, s_n):
    """The closure's compliance, minus the derivative of closure_aperture in
    s_n, K_ni V_m^2/(K_ni V_m + s_n)^2 (m/Pa): the fault's fixed-stress L_f
    of a closed cell, whose s_n falls as much as its p_f rises."""
    stiffness = closure.K_ni * closure.V_m + np.maximum(s_n, 0.0)
    return closure.K_ni * closure.V_m * closure.V_m / (stiffness * stiffness)


def open_patches(links, is_open):
    """The open patches of a fault: per cell the index of the patch of open
    cells joined by any of `links` (FaultEdges) that holds it, -1 where the
    cell is closed."""
    parent = np.arange(len(is_open))

    def root(k):
        while parent[k] != k:
            parent[k] = parent[parent[k]]
            k = parent[k]
        return k
    for k, l in (pair for edges in links for pair in edges.cells.tolist()):
        if is_open[k] and is_open[l]:
            parent[root(k)] = root(l)
    patch, number = np.full(len(is_open), -1), {}
    for k in np.flatnonzero(is_open):
        patch[k] = number.setdefault(root(k), len(number))
    return patch
