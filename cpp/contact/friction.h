// Friction as the VI's equations (theory.md, "Friction"): a frictional
// constraint's tangential rows of F(x) = K x - b become
//     F_T = R_T + P(theta) / s,   theta = -R_T s + c ds,
// the residual R plus the trial force theta (t_T + c times the slip
// increment since the step's start) projected on the disc |t| <= bound(t_N)
// (contact_law.h, project_on_disc): F_T = c ds / s where the constraint
// sticks, R_T + bound n / s where it slips, R_T where it is open. F is
// semismooth; its generalised Jacobian replaces the tangential rows of K by
// combinations of the constraint's own rows (friction_jacobian). One Newton
// solve decides open, stick and slip (Hueber, Stadler and Wohlmuth 2008).
#pragma once

#include "contact/contact_law.h"

#include <array>
#include <mpi.h>
#include <petscmat.h>
#include <vector>

namespace biotcontact
{

/// @brief A frictional constraint in the VI's numbering: the positions of
/// its normal and d - 1 tangential unknowns, the side of its bound (sign:
/// u.nu = sign x'), its gap and lumped measure, and its law.
struct FrictionalConstraint
{
  PetscInt normal = -1;
  std::array<PetscInt, 2> tangential{-1, -1};
  double sign = 1, gap = 0, lumped = 0;
  ContactLaw law;
};

/// @brief Where friction is evaluated: the VI's unknown X and residual
/// R = K X - b (both in units of the displacement scale), the unknowns at
/// the step's start (unscaled), the diagonal c of K, the scale and the
/// number of tangents (d - 1).
struct FrictionPoint
{
  const PetscScalar *X, *R, *start, *stiffness;
  double scale;
  int tangents;
};

/// @brief Friction at one constraint: closed or not, its normal traction
/// t_N (>= 0 pressing), its bound (a force: the law's times the lumped
/// measure; 0 when open), d bound / d t_N, its stiffness c (one for its
/// tangents), its slip increment and the projection of its trial force.
struct FrictionTerm
{
  bool closed = false;
  double normal = 0, bound = 0, slope = 0, stiffness = 0;
  std::array<double, 2> increment{0, 0};
  DiscProjection projection;
};

/// Friction at constraint f.
FrictionTerm friction_term(const FrictionalConstraint& f, const FrictionPoint& at);

/// F += P(theta) / s on the tangential rows of the constraints (F holds R
/// on entry).
void add_friction_forces(const std::vector<FrictionalConstraint>& constraints, const FrictionPoint& at,
                         PetscScalar* F);

/// J = K but on the tangential rows of the constraints, there the
/// generalised Jacobian of F_T: with D = dP/dtheta and g = dP/dbound,
///     J_T = (I - D) K_T + c D - slope sign g K_N,
/// combinations of the constraint's own rows of K (collective). Returns
/// PETSc's error code: it runs inside SNES's Jacobian callback.
PetscErrorCode friction_jacobian(const std::vector<FrictionalConstraint>& constraints, const FrictionPoint& at,
                                 Mat K, Mat J);

/// The weights of the generalised Jacobian's rows (friction_jacobian), 5
/// per tangential row in the constraints' order: of K's rows T_q, of the
/// diagonal and of row N. J is K but for them, so while K stays, equal
/// weights make an equal J (in 2D they change only with a constraint's
/// state; in 3D also with a slip's direction).
std::vector<double> jacobian_weights(const std::vector<FrictionalConstraint>& constraints, const FrictionPoint& at);

/// Every rank's constraints on every rank, in rank order (collective): a
/// record of plain values, gathered as bytes.
std::vector<FrictionalConstraint> all_gather_constraints(const std::vector<FrictionalConstraint>& mine,
                                                         MPI_Comm comm);

} // namespace biotcontact
