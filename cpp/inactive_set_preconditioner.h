// Algebraic multigrid for the Newton steps of the contact VI on the full
// system (contact.h, the iterative path).
//
// Each step of the reduced-space method solves A_II dx_I = -F_I on the
// inactive set I (every DOF not held on its bound). PETSc extracts A_II with
// MatCreateSubMatrix, which keeps neither the block size nor the
// near-nullspace of A, so AMG applied to it aggregates scalar DOFs with the
// constant vector and loses the rigid-body modes that make it scale for
// elasticity. Instead, with J the active DOFs, this preconditioner works on
//     A_D = [ A_II  0 ]
//           [ 0     I ]   (A with the rows and columns of J made identity),
// the matrix of the same elasticity problem with the active DOFs held like
// Dirichlet DOFs. A_D keeps A's block size (d) and its rigid-body near-
// nullspace, and (A_D)^-1 restricted to I is exactly A_II^-1, so
//     P^-1 r_I = R_I AMG(A_D)^-1 R_I^T r_I
// is AMG on A_II with node aggregates and the rigid-body coarse spaces.
// It is set up when PETSc sets the reduced KSP up, which SNES VI does only
// when the inactive set changes (the lagged preconditioner, contact.cpp);
// A_D is rebuilt in place (same nonzero pattern) and the AMG keeps its
// prolongators by default (-<prefix>pc_gamg_reuse_interpolation), so a
// change of the active set costs a Galerkin product, not a new hierarchy.
#pragma once

#include <mpi.h>
#include <petscsnes.h>
#include <string>

namespace biotcontact
{

class InactiveSetPreconditioner
{
public:
  /// Installs itself as the preconditioner of the Newton steps of `snes`
  /// (a vinewtonrsls on the matrix A). The inner AMG reads the options of
  /// `prefix` (-<prefix>pc_type gamg, -<prefix>mg_levels_...); the PC of the
  /// reduced KSP takes the prefix <prefix>inactive_.
  InactiveSetPreconditioner(SNES snes, Mat A, const std::string& prefix);
  ~InactiveSetPreconditioner();
  InactiveSetPreconditioner(const InactiveSetPreconditioner&) = delete;
  InactiveSetPreconditioner& operator=(const InactiveSetPreconditioner&) = delete;

  /// Set-ups of the inner AMG so far, and the seconds they took.
  long setups = 0;
  double setup_time = 0;

private:
  static PetscErrorCode set_up(PC pc);
  static PetscErrorCode apply(PC pc, Vec r, Vec y);

  SNES _snes;
  Mat _A;
  Mat _A_D = nullptr;
  PC _amg = nullptr;
  IS _inactive = nullptr;
  Vec _r_full = nullptr, _y_full = nullptr;
};

} // namespace biotcontact
