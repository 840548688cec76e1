// Static condensation of A x = b onto the contact DOFs C (docs/theory.md,
// "Solvers"; how H is formed and shared: SchurComplement).
//
// Only the contact DOFs carry bounds, so the variational inequality of
// contact.h can be posed on C alone. With I the other DOFs,
//     x_I = A_II^{-1} (b_I - A_IC y)                 for x_C = y,
// and the residual on C of that x is
//     (A x - b)_C = H y - g,   H = A_CC - A_CI A_II^{-1} A_IC,
//                              g = b_C - A_CI A_II^{-1} b_I,
// the Schur complement H (m x m, m = number of contact DOFs) and the
// condensed load g. The bound-constrained problem on (H, g) has the same
// solution y = x_C as the one on (A, b), and the same active sets.
#pragma once

#include "solvers/linear_solver.h"

#include <memory>
#include <petscmat.h>
#include <string>
#include <vector>

namespace biotcontact
{

/// @brief The Schur complement H of A on the contact DOFs, and the solves
/// around it.
///
/// A_II^{-1} is applied through one factorisation of A_C, the matrix A with
/// the rows and columns of C replaced by identity rows (C clamped): it is
/// valid for every inactive set, so the large matrix is factorised once per
/// operator, never per active-set change. H is formed once per operator from
/// m back-solves (in blocks of right-hand sides; or, from
/// partial_factorisation_from contact DOFs on, by MUMPS's partial
/// factorisation: factorise_with_schur) and kept dense and replicated on
/// every rank; each solve then costs two back-solves of A_C (one for g, one
/// to extend y to x) and a VI on the small dense H.
///
/// When each rank holds a copy of the factorisation (one rank, or
/// PCREDUNDANT on several, solver.h), A and A_C are gathered whole on every
/// rank and factorised there with the options of the factorisation
/// (<prefix>redundant_ on several ranks); each rank then forms its share of
/// H's columns, m / ranks of them, and the ranks exchange them. Otherwise
/// (MUMPS across the ranks) every column is one distributed back-solve.
class SchurComplement
{
public:

  /// `dofs` are the owned contact DOFs of this rank (local indices of a
  /// vector like A's columns); the factorisation of A_C uses the options
  /// with `prefix`, as A's own solver would.
  SchurComplement(MPI_Comm comm, const std::string& prefix, Mat A, Structure structure,
                  std::vector<std::int32_t> dofs);
  ~SchurComplement();
  SchurComplement(const SchurComplement&) = delete;
  SchurComplement& operator=(const SchurComplement&) = delete;

  /// Factorises A_C and forms H from the current values of A (collective).
  void assemble();

  /// H: dense m x m on PETSC_COMM_SELF, the same on every rank.
  Mat matrix() const { return _H; }
  /// m, the number of contact DOFs over all ranks.
  PetscInt size() const { return _m; }
  /// The position in H of this rank's first contact DOF.
  PetscInt offset() const { return _offset; }

  /// g = b_C - A_CI A_II^{-1} b_I on every rank (one back-solve; collective).
  void condensed_load(Vec b, Vec g);
  /// y = x_C on every rank (collective).
  void restrict_to_contact(Vec x, Vec y);
  /// x with x_C = y and x_I = A_II^{-1} (b_I - A_IC y) (one back-solve).
  void extend(Vec b, Vec y, Vec x);

  /// all[offset() + k] = local[k] from every rank, all of size m (collective).
  void gather(const PetscScalar* local, PetscScalar* all) const;

  /// From this many contact DOFs on, H comes from MUMPS's partial
  /// factorisation (factorise_with_schur): it costs 2.2 (2D) to 4 (3D)
  /// factorisations of A, as much as about 250 (2D) to 550 (3D) of the
  /// back-solves it saves (docs/performance.md, 2026-11-28).
  PetscInt partial_factorisation_from = 400;

  /// Right-hand sides solved to form H, partial factorisations that left
  /// it, and the time it took after the factorisation of A_C (s).
  long columns = 0, factorizations = 0;
  double time = 0;

private:
  /// The columns [first, first + count) of H (this rank's share when each
  /// rank solves with the whole matrix, collective otherwise).
  void form_columns(PetscInt first, PetscInt count);
  /// The matrix this rank solves with and multiplies by: A itself, or on
  /// several ranks with a copy of the factorisation on each, A gathered.
  void gather_whole();
  /// A_C x = b for x and b of A's layout, with the whole copy when each
  /// rank holds one.
  void solve(Vec x, Vec b);
  /// Values at the contact DOFs of a column solve's vectors, in H's order,
  /// on every rank (all of them, or gathered from each rank's own).
  void contact_values(const PetscScalar* at_contact, PetscScalar* all) const;
  /// H from a factorisation of S (A, or A gathered) by MUMPS with the
  /// contact DOFs as its Schur variables: the partial factorisation leaves
  /// H as its last dense block, where m back-solves cost about m / 100
  /// factorisations. Returns PETSc's error code (PETSC_ERR_SUP without
  /// MUMPS or for an A that is not SPD): then the columns are solved.
  PetscErrorCode factorise_with_schur(Mat S);
  /// Each rank's columns of H to every rank.
  void share_columns();
  /// Where a column solve's vectors hold the i-th of `_rows`.
  PetscInt local_index(std::size_t i) const;
  /// The column (and row) of H of the i-th of `_rows`.
  PetscInt column_of(std::size_t i) const;

  MPI_Comm _comm;
  std::string _prefix;
  Mat _A, _clamped = nullptr, _H = nullptr;
  Structure _structure;
  std::unique_ptr<LinearSolver> _solver;
  std::vector<std::int32_t> _dofs;
  std::vector<int> _counts, _displacements; // of each rank's contact DOFs in H
  PetscInt _m = 0, _offset = 0, _first_row = 0;
  Vec _v, _w;

  // Each rank solves with the whole matrix (one rank, or PCREDUNDANT).
  bool _whole = false;
  int _rank = 0, _ranks = 1;
  Mat _A_whole = nullptr;                 // A gathered (several ranks only)
  VecScatter _to_all = nullptr;           // a vector of A's layout -> whole
  Vec _b_whole = nullptr, _x_whole = nullptr;
  std::vector<PetscInt> _rows;            // contact rows of H's columns' solves, in H's order
  Mat solve_matrix() const { return _A_whole ? _A_whole : _A; }
};

} // namespace biotcontact
