// The preconditioner of the Newton steps of the contact VI on the full
// system (contact.h, the iterative path): algebraic multigrid for the
// mechanics, the fixed-stress sweep for the coupled system.
//
// Each step of the reduced-space method solves A_II dx_I = -F_I on the
// inactive set I (every DOF not held on its bound). With J the active DOFs
// and P the matrix the preconditioner is built from (A itself, or the
// fixed-stress matrix of the coupled system), it works on P_D, P with the
// rows and columns of J made identity, whose inverse restricted to I is
// exactly P_II^-1: with B the inner preconditioner of P_D (-<prefix>pc_type)
//     B_I^-1 r_I = R_I B(P_D)^-1 R_I^T r_I.
// Why not A_II itself, and when it is set up: InactiveSetPreconditioner.
#pragma once

#include "solvers/field_split.h"

#include <mpi.h>
#include <petscsnes.h>
#include <string>
#include <vector>

namespace biotcontact
{

/// @brief The system's own preconditioner applied to the inactive-set
/// system through P_D.
///
/// PETSc extracts A_II with MatCreateSubMatrix, which keeps neither the
/// block size nor the near-nullspace of A, so AMG applied to it aggregates
/// scalar DOFs with the constant vector and loses the rigid-body modes that
/// make it scale for elasticity; nor does it keep the field splits of a
/// mixed system. Instead it works on
///     P_D = [ P_II  0 ]
///           [ 0     I ]   (P with the rows and columns of J made identity),
/// the matrix of the same problem with the active DOFs held like Dirichlet
/// DOFs. P_D keeps P's numbering, block size, near-nullspace and fields, and
/// (P_D)^-1 restricted to I is exactly P_II^-1, so with B the inner
/// preconditioner of P_D (the system's own: -<prefix>pc_type) B_I is that
/// preconditioner applied to the inactive-set system: for the mechanics AMG
/// with node aggregates and the rigid-body coarse spaces.
///
/// It is set up when PETSc sets the reduced KSP up, which SNES VI does only
/// when the inactive set changes (the lagged preconditioner, contact.cpp);
/// P_D is rebuilt in place (same nonzero pattern) and GAMG keeps its
/// prolongators by default (-<prefix>pc_gamg_reuse_interpolation), so a
/// change of the active set costs a Galerkin product, not a new hierarchy.
class InactiveSetPreconditioner
{
public:
  /// Installs itself as the preconditioner of the Newton steps of `snes`
  /// (a vinewtonrsls), built from P; `fields` are P's splits when its
  /// preconditioner is a field split. The inner preconditioner reads the
  /// options of `prefix` (-<prefix>pc_type, -<prefix>mg_levels_...); the PC
  /// of the reduced KSP takes the prefix <prefix>inactive_. With
  /// `row_weights` W (or nullptr) the Newton steps are of W A: it is built
  /// from W P.
  InactiveSetPreconditioner(SNES snes, Mat P, const std::vector<Field>& fields, Vec row_weights,
                            const std::string& prefix);
  ~InactiveSetPreconditioner();
  InactiveSetPreconditioner(const InactiveSetPreconditioner&) = delete;
  InactiveSetPreconditioner& operator=(const InactiveSetPreconditioner&) = delete;

  /// Set-ups of the inner preconditioner so far, and the seconds they took.
  long setups = 0;
  double setup_time = 0;

private:
  static PetscErrorCode set_up(PC pc);
  static PetscErrorCode apply(PC pc, Vec r, Vec y);

  SNES _snes;
  Mat _P;
  Vec _row_weights; // W of the Newton steps W A (not owned), or nullptr
  Mat _P_D = nullptr;
  PC _inner = nullptr;
  IS _inactive = nullptr;
  Vec _r_full = nullptr, _y_full = nullptr;
};

} // namespace biotcontact
