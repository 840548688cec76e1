// Unit tests of the contact law (cpp/contact/contact_law.h): the bound of
// the tangential traction, frictionless (0), Coulomb (cohesion + friction
// t_N, no friction from a pulling t_N) and Tresca (tau, whatever the rest);
// and the state of a constraint: open whenever it is not closed, a closed
// frictionless one slips, a closed frictional one sticks below its bound
// by more than the tolerance and slips on it (within the tolerance, or past
// it by round-off). The prototype's twin is tests/unit/test_contact_law.py.
#include "contact/contact_law.h"

#include <gtest/gtest.h>

using namespace biotcontact;

namespace
{
// Coulomb with mu = 0.6 and c = 1 MPa: at t_N = 10 MPa the bound is
// 1 + 0.6 * 10 = 7 MPa.
const ContactLaw coulomb{0.6, 1e6, {}};
constexpr double pressed = 10e6, bound = 7e6, scale = 10e6;
const double margin = status_tolerance * scale; // 0.1 Pa

PairStatus status(const ContactLaw& law, bool closed, double tangential)
{
  return pair_status(law, {closed, pressed, tangential, scale});
}
} // namespace

TEST(ContactLaw, StatusValues)
{
  // fault.xdmf's `state` writes these numbers.
  EXPECT_EQ(static_cast<int>(PairStatus::open), 0);
  EXPECT_EQ(static_cast<int>(PairStatus::stick), 1);
  EXPECT_EQ(static_cast<int>(PairStatus::slip), 2);
}

TEST(ContactLaw, FrictionlessBoundIsZero)
{
  const ContactLaw frictionless;
  EXPECT_EQ(frictionless.friction, 0.0);
  EXPECT_EQ(frictionless.cohesion, 0.0);
  EXPECT_FALSE(frictionless.tresca);
  for (double normal : {-1e6, 0.0, 1e6, 1e9})
    EXPECT_EQ(slip_bound(frictionless, normal), 0.0);
}

TEST(ContactLaw, CoulombBound)
{
  EXPECT_DOUBLE_EQ(slip_bound(coulomb, pressed), bound);
  EXPECT_DOUBLE_EQ(slip_bound(coulomb, 0.0), 1e6);
  // A pulling normal traction adds no friction: the cohesion alone.
  EXPECT_DOUBLE_EQ(slip_bound(coulomb, -5e6), 1e6);
  EXPECT_DOUBLE_EQ(slip_bound(ContactLaw{0.6, 0.0, {}}, pressed), 6e6);
}

TEST(ContactLaw, TrescaReplacesFrictionAndCohesion)
{
  const ContactLaw tresca{0.6, 1e6, 2e6};
  for (double normal : {-5e6, 0.0, pressed, 1e9})
    EXPECT_EQ(slip_bound(tresca, normal), 2e6);
  EXPECT_EQ(slip_bound(ContactLaw{0, 0, 0.0}, pressed), 0.0);
}

TEST(ContactLaw, OpenWheneverNotClosed)
{
  for (const ContactLaw& law : {ContactLaw{}, coulomb, ContactLaw{0, 0, 2e6}})
    for (double tangential : {0.0, 1e6, 1e9})
      EXPECT_EQ(status(law, false, tangential), PairStatus::open);
}

TEST(ContactLaw, ClosedFrictionlessSlips)
{
  // Bound 0: no |t_T| lies below it, round-off or none.
  for (double tangential : {0.0, 1e-9, 1e3})
    EXPECT_EQ(status(ContactLaw{}, true, tangential), PairStatus::slip);
  EXPECT_EQ(pair_status(ContactLaw{}, {true, 0.0, 0.0, 0.0}), PairStatus::slip);
}

TEST(ContactLaw, StickBelowTheBoundSlipOnIt)
{
  EXPECT_EQ(status(coulomb, true, 0.0), PairStatus::stick);
  EXPECT_EQ(status(coulomb, true, bound - 2 * margin), PairStatus::stick);
  // Within the tolerance of the bound, on it, and past it by round-off.
  EXPECT_EQ(status(coulomb, true, bound - 0.5 * margin), PairStatus::slip);
  EXPECT_EQ(status(coulomb, true, bound), PairStatus::slip);
  EXPECT_EQ(status(coulomb, true, bound + margin), PairStatus::slip);
  // Tresca: the same against tau.
  const ContactLaw tresca{0, 0, 2e6};
  EXPECT_EQ(status(tresca, true, 2e6 - 2 * margin), PairStatus::stick);
  EXPECT_EQ(status(tresca, true, 2e6), PairStatus::slip);
}
