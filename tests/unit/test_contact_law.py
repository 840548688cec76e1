"""Unit tests of the prototype's contact law
(python_prototype/contact/contact_law.py), the twins of
tests/unit/test_contact_law.cpp: the bound of the tangential traction,
frictionless (0), Coulomb (cohesion + friction t_N, no friction from a
pulling t_N) and Tresca (tau, whatever the rest); and the state of a
constraint: open whenever it is not closed, a closed frictionless one slips,
a closed frictional one sticks below its bound by more than the tolerance
and slips on it (within the tolerance, or past it by round-off)."""
import os
import sys
import unittest

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
import support  # noqa: E402,F401  (the repository on sys.path)
from python_prototype.contact.contact_law import (STATUS_TOLERANCE, ContactLaw, PairStatus,  # noqa: E402
                                                  PairTraction, pair_status, slip_bound)

# Coulomb with mu = 0.6 and c = 1 MPa: at t_N = 10 MPa the bound is
# 1 + 0.6 * 10 = 7 MPa.
COULOMB = ContactLaw(0.6, 1e6)
PRESSED, BOUND, SCALE = 10e6, 7e6, 10e6
MARGIN = STATUS_TOLERANCE * SCALE  # 0.1 Pa


def status(law, closed, tangential):
    return pair_status(law, PairTraction(closed, PRESSED, tangential, SCALE))


class ContactLawTest(unittest.TestCase):
    def test_status_values(self):
        # fault.xdmf's `state` writes these numbers.
        self.assertEqual([int(PairStatus.open), int(PairStatus.stick), int(PairStatus.slip)], [0, 1, 2])

    def test_frictionless_bound_is_zero(self):
        frictionless = ContactLaw()
        self.assertEqual((frictionless.friction, frictionless.cohesion, frictionless.tresca), (0.0, 0.0, None))
        for normal in (-1e6, 0.0, 1e6, 1e9):
            self.assertEqual(slip_bound(frictionless, normal), 0.0)

    def test_coulomb_bound(self):
        self.assertAlmostEqual(slip_bound(COULOMB, PRESSED), BOUND, delta=1e-9)
        self.assertAlmostEqual(slip_bound(COULOMB, 0.0), 1e6, delta=1e-9)
        # A pulling normal traction adds no friction: the cohesion alone.
        self.assertAlmostEqual(slip_bound(COULOMB, -5e6), 1e6, delta=1e-9)
        self.assertAlmostEqual(slip_bound(ContactLaw(0.6, 0.0), PRESSED), 6e6, delta=1e-9)

    def test_tresca_replaces_friction_and_cohesion(self):
        tresca = ContactLaw(0.6, 1e6, 2e6)
        for normal in (-5e6, 0.0, PRESSED, 1e9):
            self.assertEqual(slip_bound(tresca, normal), 2e6)
        self.assertEqual(slip_bound(ContactLaw(0, 0, 0.0), PRESSED), 0.0)

    def test_open_whenever_not_closed(self):
        for law in (ContactLaw(), COULOMB, ContactLaw(0, 0, 2e6)):
            for tangential in (0.0, 1e6, 1e9):
                self.assertEqual(status(law, False, tangential), PairStatus.open)

    def test_closed_frictionless_slips(self):
        # Bound 0: no |t_T| lies below it, round-off or none.
        for tangential in (0.0, 1e-9, 1e3):
            self.assertEqual(status(ContactLaw(), True, tangential), PairStatus.slip)
        self.assertEqual(pair_status(ContactLaw(), PairTraction(True, 0.0, 0.0, 0.0)), PairStatus.slip)

    def test_stick_below_the_bound_slip_on_it(self):
        self.assertEqual(status(COULOMB, True, 0.0), PairStatus.stick)
        self.assertEqual(status(COULOMB, True, BOUND - 2 * MARGIN), PairStatus.stick)
        # Within the tolerance of the bound, on it, and past it by round-off.
        self.assertEqual(status(COULOMB, True, BOUND - 0.5 * MARGIN), PairStatus.slip)
        self.assertEqual(status(COULOMB, True, BOUND), PairStatus.slip)
        self.assertEqual(status(COULOMB, True, BOUND + MARGIN), PairStatus.slip)
        # Tresca: the same against tau.
        tresca = ContactLaw(0, 0, 2e6)
        self.assertEqual(status(tresca, True, 2e6 - 2 * MARGIN), PairStatus.stick)
        self.assertEqual(status(tresca, True, 2e6), PairStatus.slip)


if __name__ == "__main__":
    unittest.main()
