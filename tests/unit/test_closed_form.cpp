// Unit tests of the closed forms of a split fault (cpp/diagnostics/
// closed_form.h): Sneddon's openings (plane strain and penny-shaped) and
// Jansen and Meulenbroek's slip at chosen points against hand computations,
// zero outside the crack and beyond the reservoir, the slip continuous at
// |y| = a and |y| = b, reversed by injection, and the published peak. The
// prototype's twin is tests/unit/test_closed_form.py.
#include "diagnostics/closed_form.h"

#include <cmath>
#include <gtest/gtest.h>

using namespace biotcontact;

namespace
{
// The displaced fault of Novikov et al. (2024) and GEOS's slippedVerticalFault
// case: E = 14.95 GPa and nu = 0.15 (G = 6.5 GPa), alpha = 0.9, dp = -25 MPa.
const DisplacedFault fault{75, 150};
constexpr double E = 14.95e9, nu = 0.15, alpha = 0.9, dp = -25e6;
// The plateau by hand: (1 - 2 nu) alpha |dp| (b - a) / G
// = 0.7 * 0.9 * 25e6 * 75 / 6.5e9 = 1.18125e9 / 6.5e9.
constexpr double plateau = 1.18125e9 / 6.5e9;

double slip(double y, double pressure_change = dp)
{
  return jansen_meulenbroek_slip(y, fault, E, nu, alpha, pressure_change);
}
} // namespace

TEST(ClosedForm, SneddonOpeningAtPoints)
{
  // p = 2 MPa, E = 10 GPa, nu = 0.25, a = 1: 4 (1 - nu^2) p / E = 4 * 0.9375 * 2e-4
  // = 7.5e-4 at the centre, times sqrt(1 - 0.6^2) = 0.8 at s = 0.6.
  EXPECT_NEAR(sneddon_opening(2e6, 1e10, 0.25, 1, 0), 7.5e-4, 1e-18);
  EXPECT_NEAR(sneddon_opening(2e6, 1e10, 0.25, 1, 0.6), 6.0e-4, 1e-18);
  EXPECT_NEAR(sneddon_opening(2e6, 1e10, 0.25, 1, -0.6), 6.0e-4, 1e-18);
  // The half-length scales the opening: a = 2, s = 1.2 is twice a = 1, s = 0.6.
  EXPECT_NEAR(sneddon_opening(2e6, 1e10, 0.25, 2, 1.2), 1.2e-3, 1e-18);
}

TEST(ClosedForm, PennyOpeningAtPoints)
{
  // p = 1 MPa, E = 10 GPa, nu = 0.25, a = 2: 8 (1 - nu^2) p / (pi E) a
  // = 7.5e-4 * 2 / pi at the centre, 7.5e-4 * sqrt(4 - 1.44) / pi = 1.2e-3 / pi at r = 1.2.
  EXPECT_NEAR(penny_opening(1e6, 1e10, 0.25, 2, 0), 1.5e-3 / M_PI, 1e-18);
  EXPECT_NEAR(penny_opening(1e6, 1e10, 0.25, 2, 1.2), 1.2e-3 / M_PI, 1e-18);
  // The penny opens 2/pi as wide as the plane-strain crack of the same size.
  EXPECT_NEAR(penny_opening(1e6, 1e10, 0.25, 2, 0) / sneddon_opening(1e6, 1e10, 0.25, 2, 0), 2 / M_PI, 1e-15);
}

TEST(ClosedForm, OpeningsAreZeroOutsideTheCrack)
{
  for (double s : {1.0, -1.0, 1.5, -3.0, 100.0})
  {
    EXPECT_EQ(sneddon_opening(2e6, 1e10, 0.25, 1, s), 0.0) << "s = " << s;
    EXPECT_EQ(penny_opening(2e6, 1e10, 0.25, 1, std::abs(s)), 0.0) << "r = " << s;
  }
}

TEST(ClosedForm, JansenMeulenbroekSlipAtPoints)
{
  for (double y : {0.0, 40.0, -40.0, 75.0, -75.0})
    EXPECT_NEAR(slip(y), plateau, 1e-15) << "the plateau on |y| <= a, y = " << y;
  // Linear from a to b: at |y| = 100, (150 - 100) / (150 - 75) = 2/3 of the plateau.
  EXPECT_NEAR(slip(100), plateau * 2 / 3, 1e-15);
  EXPECT_NEAR(slip(-100), plateau * 2 / 3, 1e-15);
  for (double y : {150.0, -150.0, 200.0, -1000.0})
    EXPECT_EQ(slip(y), 0.0) << "no slip beyond the reservoir, y = " << y;
  // The published peak (Novikov et al. 2024, GEOS): 0.18173 m.
  EXPECT_NEAR(slip(0), 0.18173, 1e-5);
  // Injection reverses it.
  EXPECT_NEAR(slip(0, 25e6), -plateau, 1e-15);
}

TEST(ClosedForm, JansenMeulenbroekSlipIsContinuousAtTheCorners)
{
  // The slope on a < |y| < b is plateau / (b - a): across each corner the
  // slip changes by at most that times the step.
  const double slope = plateau / 75, h = 1e-9;
  for (double corner : {75.0, -75.0, 150.0, -150.0})
  {
    EXPECT_NEAR(slip(corner - h), slip(corner + h), 2.01 * slope * h) << "y = " << corner;
    EXPECT_NEAR(slip(corner - h), slip(corner), 1.01 * slope * h) << "y = " << corner;
  }
}
