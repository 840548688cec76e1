"""Closed-form solutions for verification (cpp/diagnostics/closed_form.cpp), vectorised
over the coordinate: Terzaghi consolidation, Mandel's problem, the opening of
Sneddon's pressurised cracks (plane strain and penny-shaped) and the slip of
Jansen and Meulenbroek's displaced fault."""
import dataclasses
import math
from dataclasses import dataclass

import numpy as np

from ..scene.expression import Expression
from ..scene.input import ReferenceSolution


@dataclass
class Terzaghi:
    """A column of height h, base fixed and impermeable, top drained and
    loaded by the compressive traction `load` from t = 0+."""
    h: float
    G: float
    lmbda: float
    alpha: float
    storage: float
    mobility: float  # k / mu_f
    load: float

    def m_v(self):
        return 1.0 / (self.lmbda + 2 * self.G)

    def consolidation_coefficient(self):
        return self.mobility / (self.storage + self.alpha ** 2 * self.m_v())

    def initial_pressure(self):
        return self.alpha * self.m_v() * self.load / (self.storage + self.alpha ** 2 * self.m_v())

    def _series(self, z, t, term):
        """Fourier series at heights z, summed until the exponential factor
        drops below round-off (at t = 0 cut at 20000 terms)."""
        c, h, total = self.consolidation_coefficient(), self.h, np.zeros(np.shape(z))
        for j in range(1, 20001):
            k = 2 * j - 1
            decay = math.exp(-k * k * math.pi * math.pi * c * t / (4 * h * h))
            if decay < 1e-18:
                break
            total = total + term(j, k) * decay
        return total

    def pressure(self, z, t):
        sign = lambda j: 1.0 if j % 2 == 1 else -1.0  # noqa: E731
        return 4 * self.initial_pressure() / math.pi * self._series(
            z, t, lambda j, k: sign(j) / k * np.cos(k * math.pi * z / (2 * self.h)))

    def displacement(self, z, t):
        """Vertical displacement (upward positive): uniaxial strain,
        u(z) = m_v (alpha int_0^z p ds - load z)."""
        h = self.h
        sign = lambda j: 1.0 if j % 2 == 1 else -1.0  # noqa: E731
        integral = 4 * self.initial_pressure() / math.pi * self._series(
            z, t, lambda j, k: sign(j) / k * (2 * h / (k * math.pi)) * np.sin(k * math.pi * z / (2 * h)))
        return self.m_v() * (self.alpha * integral - self.load * z)

    def settlement(self, t):
        """Settlement of the top, downward positive."""
        return -self.displacement(self.h, t)


@dataclass
class Medium:
    """The homogeneous poroelastic medium of a closed form: shear modulus G,
    Lame's lambda, Biot's alpha, storage S, mobility k/mu_f."""
    G: float
    lmbda: float
    alpha: float
    storage: float
    mobility: float


class Mandel:
    """Mandel's problem in plane strain on the quarter 0 <= x <= a, 0 <= y <= b
    (symmetry on x = 0 and y = 0), drained at x = a, a compressive force 2F
    per unit thickness through a rigid frictionless plate at y = b, applied
    at t = 0+ (docs/verification.md, "Mandel"), in the Medium `medium`."""

    def __init__(self, a, b, medium, F):
        G, lmbda, alpha, storage, mobility = medium.G, medium.lmbda, medium.alpha, medium.storage, medium.mobility
        self.a, self.b, self.G, self.F = a, b, G, F
        K = lmbda + 2 * G / 3  # drained bulk modulus (3D)
        nu = self.nu = (3 * K - 2 * G) / (2 * (3 * K + G))
        K_u = K + alpha * alpha / storage
        B = self.B = alpha / (storage * K_u)
        nu_u = self.nu_u = (3 * nu + B * (1 - 2 * nu)) / (3 - B * (1 - 2 * nu))
        self.consolidation_coefficient = (2 * mobility * B * B * G * (1 - nu) * (1 + nu_u) * (1 + nu_u)
                                          / (9 * (1 - nu_u) * (nu_u - nu)))
        # Roots of tan x = c x, one in each ((n-1) pi, (n-1) pi + pi/2) (c > 1), by bisection.
        c = (1 - nu) / (nu_u - nu)
        self.roots = []
        for n in range(1, 401):
            lo, hi = (n - 1) * math.pi + 1e-12, (n - 1) * math.pi + math.pi / 2 - 1e-12
            for _ in range(200):
                mid = 0.5 * (lo + hi)
                if math.tan(mid) - c * mid < 0:
                    lo = mid
                else:
                    hi = mid
            self.roots.append(0.5 * (lo + hi))

    def _decay(self, an, t):
        return math.exp(-an * an * self.consolidation_coefficient * t / (self.a * self.a))

    def _terms(self, t):
        """The roots whose decay factor is >= 1e-18: the rest of each series
        is below round-off (cpp/diagnostics/closed_form.cpp, series_cut)."""
        return [an for an in self.roots if self._decay(an, t) >= 1e-18]

    def _series(self, t, term):
        """sum_n term(a_n, a_n - sin a_n cos a_n) E_n(t)."""
        total = 0.0
        for an in self._terms(t):
            total = total + term(an, an - math.sin(an) * math.cos(an)) * self._decay(an, t)
        return total

    def pressure(self, x, t):
        total = self._series(t, lambda an, D: math.sin(an) / D * (np.cos(an * x / self.a) - math.cos(an)))
        return 2 * self.F * self.B * (1 + self.nu_u) / (3 * self.a) * total

    def _plate_series(self, t):
        """The plate's part of both displacements."""
        return self._series(t, lambda an, D: math.sin(an) * math.cos(an) / D)

    def displacement_x(self, x, t):
        s2 = self._series(t, lambda an, D: math.cos(an) / D * np.sin(an * x / self.a))
        F, G, a = self.F, self.G, self.a
        return (F * self.nu / (2 * G * a) - F * self.nu_u / (G * a) * self._plate_series(t)) * x + F / G * s2

    def displacement_y(self, y, t):
        F, G, a = self.F, self.G, self.a
        return (-F * (1 - self.nu) / (2 * G * a) + F * (1 - self.nu_u) / (G * a) * self._plate_series(t)) * y


def sneddon_opening(p, E, nu, a, s):
    """Sneddon's pressurised crack in plane strain (Sneddon 1946; Sneddon and
    Lowengrub 1969, section 2.5; docs/verification.md, "Sneddon"): the total
    opening (both faces) of a straight crack of half-length a in an unbounded
    plane (Young's modulus E, Poisson's ratio nu) under the internal pressure
    p, at the distance s from its centre along it:
    w(s) = 4 (1 - nu^2) p / E sqrt(a^2 - s^2), zero for |s| >= a."""
    return 4 * (1 - nu * nu) * p / E * np.sqrt(np.maximum(a * a - np.square(s), 0.0))


def penny_opening(p, E, nu, a, r):
    """Sneddon's penny-shaped crack (Sneddon 1946; docs/verification.md,
    "Penny-shaped crack"): the total opening of a disc-shaped crack of radius
    a in an unbounded body under the internal pressure p, at the distance r
    from its centre: w(r) = 8 (1 - nu^2) p / (pi E) sqrt(a^2 - r^2), zero for
    r >= a."""
    return 8 * (1 - nu * nu) * p / (math.pi * E) * np.sqrt(np.maximum(a * a - np.square(r), 0.0))


@dataclass
class DisplacedFault:
    """The geometry of Jansen and Meulenbroek's displaced fault: a vertical
    fault at x = 0 offsets a laterally unbounded reservoir, which spans
    -b <= y <= a on its left (x < 0) and -a <= y <= b on its right (x > 0),
    0 <= a < b: thickness a + b, throw b - a."""
    a: float
    b: float


def jansen_meulenbroek_slip(y, fault, E, nu, alpha, dp):
    """The slip of a frictionless vertical fault offsetting a reservoir whose
    pressure changes by dp (plane strain, unbounded plane, Biot's alpha;
    Jansen and Meulenbroek 2022, "Induced aseismic slip and the onset of
    seismicity in displaced faults", Netherlands Journal of Geosciences, the
    slip for zero friction; docs/verification.md, "Jansen and Meulenbroek"):
    the vertical displacement of the fault's right face relative to its left
    one, u_y(0+, y) - u_y(0-, y), a trapezoid:
    -(1 - 2 nu) alpha dp / G (b - a) on |y| <= a, falling linearly to zero at
    |y| = b, zero beyond, G = E / (2 (1 + nu)). Positive for depletion
    (dp < 0): each block's reservoir compacts towards its own mid-height, so
    in the overlap the right block, whose reservoir lies higher, moves up.

    It is the trapezoid times C/A in size, with C = (1 - 2 nu) alpha dp / (2 pi (1 - nu))
    the scale of the shear stress the depletion puts on a locked fault and
    A = G / (2 pi (1 - nu)) that of an edge dislocation's: a slip gradient of
    size |C|/A, of opposite signs on -b < y < -a and a < y < b, cancels the
    locked fault's logarithmic shear stress everywhere on the line x = 0."""
    G = E / (2 * (1 + nu))
    return -(1 - 2 * nu) * alpha * dp / G * np.clip(fault.b - np.abs(y), 0.0, fault.b - fault.a)


def with_mandel_plate(scene):
    """The scene a run solves: `scene` itself, or for a [reference] solution
    = "mandel" scene a copy with Mandel's rigid frictionless plate imposed
    as the exact u_y on the boundary reference.plate (the usual set-up;
    docs/verification.md), which the reader checked is free."""
    if scene.reference is None or scene.reference.solution != ReferenceSolution.mandel:
        return scene
    f = scene.flow
    medium = Medium(scene.mechanics.G, scene.mechanics.lmbda, scene.coupling.alpha, f.storage(),
                    f.permeability(0, 0, 0, 0) / f.mu_f)
    mandel = Mandel(scene.mesh.upper[0], scene.mesh.upper[1], medium, scene.reference.force)
    plate = scene.boundaries[scene.reference.plate]
    displacement = list(plate.displacement)
    displacement[1] = Expression.function(lambda x, y, z, t: mandel.displacement_y(y, t),
                                          "Mandel's exact plate displacement")
    boundaries = dict(scene.boundaries)
    boundaries[scene.reference.plate] = dataclasses.replace(plate, mechanics="displacement", displacement=displacement)
    return dataclasses.replace(scene, boundaries=boundaries)
