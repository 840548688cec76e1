// Closed-form solutions for verification (docs/verification.md).
#pragma once

#include "scene/scene.h"

#include <vector>

namespace biotcontact
{

/// Terzaghi consolidation of a column of height h, base at z = 0 fixed and
/// impermeable, top drained and loaded by the compressive traction `load`
/// from t = 0+ (docs/verification.md, "Terzaghi").
struct Terzaghi
{
  double h, G, lambda, alpha, storage, mobility, load; // mobility = k/mu_f

  double m_v() const { return 1.0 / (lambda + 2 * G); }
  double consolidation_coefficient() const { return mobility / (storage + alpha * alpha * m_v()); }
  double initial_pressure() const { return alpha * m_v() * load / (storage + alpha * alpha * m_v()); }
  double pressure(double z, double t) const;
  /// Vertical displacement (upward positive) at height z.
  double displacement(double z, double t) const;
  /// Settlement of the top, downward positive.
  double settlement(double t) const { return -displacement(h, t); }
};

/// @brief The homogeneous poroelastic medium of a closed form: shear
/// modulus G, Lame's lambda, Biot's alpha, storage S, mobility k/mu_f.
struct Medium
{
  double G, lambda, alpha, storage, mobility;
};

/// Mandel's problem in plane strain on the quarter 0 <= x <= a, 0 <= y <= b
/// (symmetry on x = 0 and y = 0), drained at x = a, a compressive force 2F
/// per unit thickness through a rigid frictionless plate at y = b, applied
/// at t = 0+ (docs/verification.md, "Mandel").
class Mandel
{
public:
  Mandel(double a, double b, const Medium& medium, double F);
  double pressure(double x, double t) const;
  double displacement_x(double x, double t) const;
  double displacement_y(double y, double t) const;
  double nu, nu_u, B, consolidation_coefficient;

private:
  /// sum_n term(a_n, a_n - sin a_n cos a_n) E_n(t), E_n = exp(-a_n^2 c t / a^2).
  template <typename Term>
  double series(double t, Term term) const;
  double plate_series(double t) const;
  double _a, _b, _G, _F;
  std::vector<double> _roots; // alpha_n: tan(a_n) = (1 - nu)/(nu_u - nu) a_n
};

/// Sneddon's pressurised crack in plane strain (Sneddon 1946; Sneddon and
/// Lowengrub 1969, section 2.5; docs/verification.md, "Sneddon"): the total
/// opening (both faces) of a straight crack of half-length a in an unbounded
/// plane (Young's modulus E, Poisson's ratio nu) under the internal pressure
/// p, at the distance s from its centre along it:
/// w(s) = 4 (1 - nu^2) p / E sqrt(a^2 - s^2), zero for |s| >= a.
double sneddon_opening(double p, double E, double nu, double a, double s);

/// Sneddon's penny-shaped crack (Sneddon 1946; docs/verification.md,
/// "Penny-shaped crack"): the total opening of a disc-shaped crack of radius
/// a in an unbounded body under the internal pressure p, at the distance r
/// from its centre: w(r) = 8 (1 - nu^2) p / (pi E) sqrt(a^2 - r^2), zero for
/// r >= a.
double penny_opening(double p, double E, double nu, double a, double r);

/// @brief The geometry of Jansen and Meulenbroek's displaced fault: a
/// vertical fault at x = 0 offsets a laterally unbounded reservoir, which
/// spans -b <= y <= a on its left (x < 0) and -a <= y <= b on its right
/// (x > 0), 0 <= a < b: thickness a + b, throw b - a.
struct DisplacedFault
{
  double a, b;
};

/// The slip of a frictionless vertical fault offsetting a reservoir whose
/// pressure changes by dp (plane strain, unbounded plane, Biot's alpha;
/// Jansen and Meulenbroek 2022, "Induced aseismic slip and the onset of
/// seismicity in displaced faults", Netherlands Journal of Geosciences, the
/// slip for zero friction; docs/verification.md, "Jansen and Meulenbroek"): the
/// vertical displacement of the fault's right face relative to its left
/// one, u_y(0+, y) - u_y(0-, y), a trapezoid:
/// -(1 - 2 nu) alpha dp / G (b - a) on |y| <= a, falling linearly to zero at
/// |y| = b, zero beyond, G = E / (2 (1 + nu)). Positive for depletion
/// (dp < 0): each block's reservoir compacts towards its own mid-height, so
/// in the overlap the right block, whose reservoir lies higher, moves up.
double jansen_meulenbroek_slip(double y, DisplacedFault fault, double E, double nu, double alpha, double dp);

/// The scene a run solves: `scene` itself, or for a [reference] solution =
/// "mandel" scene the scene with Mandel's rigid frictionless plate imposed
/// as the exact u_y on the boundary reference.plate (the usual set-up;
/// docs/verification.md), which the reader checked is free.
Scene with_mandel_plate(Scene scene);

} // namespace biotcontact
