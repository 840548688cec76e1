// The contact law of a pair (theory.md, "The contact law"): what the
// traction across a closed pair may be, and the state it leaves the pair in
// (open, stick or slip: PairStatus). The pairs (foundation_pair.h,
// fault_pair.h) say which nodes face which; the VI solver knows no physics.
// The bound of the tangential traction t_T (slip_bound), the exact disc in
// 3D: tresca when given, else cohesion + friction max(t_N, 0) (Coulomb);
// frictionless (the default law) bound 0: a closed pair slides freely.
// The bond: a pair's cohesion breaks for the rest of the run where its
// effective normal traction falls to zero (a tension cut-off at zero: the
// pair opens, or its solve can keep it closed only pulled); friction stays.
#pragma once

#include "scene/scene.h"

#include <array>
#include <optional>

namespace biotcontact
{

/// The state of one constraint of a pair, with the values fault.xdmf's
/// `state` writes. With g the pair's gap (the distance to the foundation;
/// the opening [u].n + g0 of a fault pair), t_N >= 0 its normal traction
/// (pressing) and t_T its tangential traction (a vector in the face, along
/// the slip increment when the pair slips), a pair is
///     open:   g > 0, no traction (t_N = 0, t_T = 0);
///     stick:  g = 0, |t_T| < bound, no slip increment;
///     slip:   g = 0, |t_T| = bound, the slip increment along t_T.
enum class PairStatus
{
  open = 0,
  stick = 1,
  slip = 2
};

/// @brief The contact law of a contact boundary or fault: Coulomb friction
/// (the coefficient mu and the cohesion c), or Tresca's bound tau, which,
/// when given, replaces both. Default: frictionless.
struct ContactLaw
{
  double friction = 0;
  double cohesion = 0;
  std::optional<double> tresca;
};

/// @brief What decides a constraint's state: whether it is closed (as the
/// VI solver decides: on the foundation, the faces touching), its normal
/// traction t_N (>= 0 pressing), the magnitude of its tangential traction
/// |t_T|, and the traction scale the tolerance is relative to.
struct PairTraction
{
  bool closed = false;
  double normal = 0;
  double tangential = 0;
  double scale = 0;
};

/// A closed constraint sticks when |t_T| is below its bound by more than
/// this, relative to the traction scale: above the error of the tractions
/// (round-off of a direct solve, the 1e-10 relative residual of an
/// iterative one), so that a slipping pair, on its bound, is not taken for
/// one that sticks.
constexpr double status_tolerance = 1e-8;

/// Whether a constraint is closed: its node lies on the foundation (the
/// faces touch) to round-off, within 1e-9 of the displacement scale (the one
/// test behind the active set the coupling compares, the contact_active
/// field and friction's bound).
inline bool on_foundation(double distance, double scale) { return distance <= 1e-9 * scale; }

/// The law a scene gives a contact boundary or a fault.
ContactLaw contact_law(const FrictionSpec& friction);

/// Whether the law holds nothing tangentially (bound 0 whatever t_N).
bool frictionless(const ContactLaw& law);

/// The bound of |t_T|: tresca if given, else cohesion + friction
/// max(t_N, 0) (a pulling t_N adds no friction).
double slip_bound(const ContactLaw& law, double normal_traction);

/// d bound / d t_N: the friction coefficient where Coulomb's bound grows
/// with t_N (t_N > 0), else 0 (Tresca, a pulling t_N).
double slip_bound_slope(const ContactLaw& law, double normal_traction);

/// @brief The friction force of a constraint: its trial force theta = t_T +
/// c s projected on the disc |t| <= bound (the return map; theory.md,
/// "Friction"), with the derivatives the semismooth Newton step needs.
/// Within the disc (bound > 0) the constraint sticks: force theta, d_trial
/// the identity; outside it slips: force bound theta/|theta|, d_trial
/// bound/|theta| (I - n n^T), d_bound n (n = theta/|theta|; 0 for theta = 0).
struct DiscProjection
{
  std::array<double, 2> force{0, 0};
  std::array<double, 4> d_trial{0, 0, 0, 0}; // row-major, tangents x tangents
  std::array<double, 2> d_bound{0, 0};
  bool stick = false;
};

/// The projection of `trial` (its first `tangents` components: 1 in 2D, 2
/// in 3D) on the disc of radius `bound` >= 0.
DiscProjection project_on_disc(double bound, const std::array<double, 2>& trial, int tangents);

/// The state of one constraint: open if it is not closed; closed, stick
/// when |t_T| < bound - status_tolerance * scale, else slip. A closed
/// frictionless constraint therefore slips (bound 0: nothing holds it,
/// and |t_T| is only the solve's error).
PairStatus pair_status(const ContactLaw& law, const PairTraction& traction);

} // namespace biotcontact
