"""Unit tests of the prototype's closed forms of a split fault
(python_prototype/diagnostics/closed_form.py), the twins of
tests/unit/test_closed_form.cpp: Sneddon's openings (plane strain and
penny-shaped) and Jansen and Meulenbroek's slip at chosen points against hand
computations, zero outside the crack and beyond the reservoir, the slip
continuous at |y| = a and |y| = b, reversed by injection, and the published
peak (and, as the prototype evaluates them, on arrays of points at once)."""
import math
import os
import sys
import unittest

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
import support  # noqa: E402,F401  (the repository on sys.path)
from python_prototype.diagnostics.closed_form import (DisplacedFault, jansen_meulenbroek_slip,  # noqa: E402
                                                      penny_opening, sneddon_opening)

# The displaced fault of Novikov et al. (2024) and GEOS's slippedVerticalFault
# case: E = 14.95 GPa and nu = 0.15 (G = 6.5 GPa), alpha = 0.9, dp = -25 MPa.
FAULT = DisplacedFault(75, 150)
E, NU, ALPHA, DP = 14.95e9, 0.15, 0.9, -25e6
# The plateau by hand: (1 - 2 nu) alpha |dp| (b - a) / G
# = 0.7 * 0.9 * 25e6 * 75 / 6.5e9 = 1.18125e9 / 6.5e9.
PLATEAU = 1.18125e9 / 6.5e9


def slip(y, dp=DP):
    return jansen_meulenbroek_slip(y, FAULT, E, NU, ALPHA, dp)


class ClosedFormTest(unittest.TestCase):
    def test_sneddon_opening_at_points(self):
        # p = 2 MPa, E = 10 GPa, nu = 0.25, a = 1: 4 (1 - nu^2) p / E = 4 * 0.9375 * 2e-4
        # = 7.5e-4 at the centre, times sqrt(1 - 0.6^2) = 0.8 at s = 0.6.
        self.assertAlmostEqual(sneddon_opening(2e6, 1e10, 0.25, 1, 0), 7.5e-4, delta=1e-18)
        self.assertAlmostEqual(sneddon_opening(2e6, 1e10, 0.25, 1, 0.6), 6.0e-4, delta=1e-18)
        self.assertAlmostEqual(sneddon_opening(2e6, 1e10, 0.25, 1, -0.6), 6.0e-4, delta=1e-18)
        # The half-length scales the opening: a = 2, s = 1.2 is twice a = 1, s = 0.6.
        self.assertAlmostEqual(sneddon_opening(2e6, 1e10, 0.25, 2, 1.2), 1.2e-3, delta=1e-18)
        # The prototype evaluates arrays of points at once.
        np.testing.assert_allclose(sneddon_opening(2e6, 1e10, 0.25, 1, np.array([-2.0, -0.6, 0.0, 0.6])),
                                   [0, 6.0e-4, 7.5e-4, 6.0e-4], atol=1e-18)

    def test_penny_opening_at_points(self):
        # p = 1 MPa, E = 10 GPa, nu = 0.25, a = 2: 8 (1 - nu^2) p / (pi E) a
        # = 7.5e-4 * 2 / pi at the centre, 7.5e-4 * sqrt(4 - 1.44) / pi = 1.2e-3 / pi at r = 1.2.
        self.assertAlmostEqual(penny_opening(1e6, 1e10, 0.25, 2, 0), 1.5e-3 / math.pi, delta=1e-18)
        self.assertAlmostEqual(penny_opening(1e6, 1e10, 0.25, 2, 1.2), 1.2e-3 / math.pi, delta=1e-18)
        # The penny opens 2/pi as wide as the plane-strain crack of the same size.
        self.assertAlmostEqual(penny_opening(1e6, 1e10, 0.25, 2, 0) / sneddon_opening(1e6, 1e10, 0.25, 2, 0),
                               2 / math.pi, delta=1e-15)
        np.testing.assert_allclose(penny_opening(1e6, 1e10, 0.25, 2, np.array([0.0, 1.2, 2.0])),
                                   [1.5e-3 / math.pi, 1.2e-3 / math.pi, 0], atol=1e-18)

    def test_openings_are_zero_outside_the_crack(self):
        for s in (1.0, -1.0, 1.5, -3.0, 100.0):
            self.assertEqual(sneddon_opening(2e6, 1e10, 0.25, 1, s), 0.0, f"s = {s}")
            self.assertEqual(penny_opening(2e6, 1e10, 0.25, 1, abs(s)), 0.0, f"r = {s}")

    def test_jansen_meulenbroek_slip_at_points(self):
        for y in (0.0, 40.0, -40.0, 75.0, -75.0):
            self.assertAlmostEqual(slip(y), PLATEAU, delta=1e-15, msg=f"the plateau on |y| <= a, y = {y}")
        # Linear from a to b: at |y| = 100, (150 - 100) / (150 - 75) = 2/3 of the plateau.
        self.assertAlmostEqual(slip(100), PLATEAU * 2 / 3, delta=1e-15)
        self.assertAlmostEqual(slip(-100), PLATEAU * 2 / 3, delta=1e-15)
        for y in (150.0, -150.0, 200.0, -1000.0):
            self.assertEqual(slip(y), 0.0, f"no slip beyond the reservoir, y = {y}")
        # The published peak (Novikov et al. 2024, GEOS): 0.18173 m.
        self.assertAlmostEqual(slip(0), 0.18173, delta=1e-5)
        # Injection reverses it.
        self.assertAlmostEqual(slip(0, 25e6), -PLATEAU, delta=1e-15)
        np.testing.assert_allclose(slip(np.array([-200.0, -100.0, 0.0, 100.0, 200.0])),
                                   [0, PLATEAU * 2 / 3, PLATEAU, PLATEAU * 2 / 3, 0], atol=1e-15)

    def test_jansen_meulenbroek_slip_is_continuous_at_the_corners(self):
        # The slope on a < |y| < b is plateau / (b - a): across each corner the
        # slip changes by at most that times the step.
        slope, h = PLATEAU / 75, 1e-9
        for corner in (75.0, -75.0, 150.0, -150.0):
            self.assertAlmostEqual(slip(corner - h), slip(corner + h), delta=2.01 * slope * h, msg=f"y = {corner}")
            self.assertAlmostEqual(slip(corner - h), slip(corner), delta=1.01 * slope * h, msg=f"y = {corner}")


if __name__ == "__main__":
    unittest.main()
