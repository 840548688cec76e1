// Closed-form solutions (../shared/docs/benchmarks.md) for verification.
#pragma once

namespace biotcontact
{

/// Terzaghi consolidation of a column of height h, base at z = 0 fixed and
/// impermeable, top drained and loaded by the compressive traction `load`
/// from t = 0+ (benchmarks.md, "Terzaghi consolidation").
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

} // namespace biotcontact
