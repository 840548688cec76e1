// Which system the contact VI is posed on (docs/theory.md, "Solvers"): the
// Schur complement of the contact DOFs (schur_complement.h) or the whole
// system, chosen by what each costs, and what answers a failed full solve.
#pragma once

#include "solvers/solver.h"

#include <mpi.h>
#include <petscsys.h>
#include <string>

namespace biotcontact
{

/// Above this many contact DOFs the dense H (m^2 doubles, m back-solves to
/// form, m^3/3 flops per active-set change) costs more than refactorising
/// the sparse inactive-set matrix.
constexpr PetscInt max_condensed_dofs = 2000;

/// @brief Where the contact VI is posed: on the Schur complement of the
/// contact DOFs, on the whole system, or on the whole system for one Newton
/// step (two with friction) and, if that did not solve it, condensed.
enum class ContactPath
{
  condensed,
  full,
  full_then_condensed
};

/// @brief What the path depends on: the system's solver, the contact DOFs
/// over all ranks, whether A changes between most solves (the monolithic
/// system with conduit faults) and whether the run solves the contact once.
struct PathCosts
{
  Method method;
  PetscInt contact_dofs;
  bool changing = false;
  bool once = false;
};

/// @brief The path, and whether a solve that fails on the whole system is
/// solved again condensed (and the run goes on condensed): where the user
/// did not choose the path and the condensed one is open (a direct solver,
/// at most max_condensed_dofs contact DOFs).
struct ContactPathChoice
{
  ContactPath path;
  bool condensed_on_failure = false;
};

/// -<prefix>contact_condensed through PETSc's options database (so that
/// -help lists it with this run's default), else condensed when the system
/// is solved directly, C is small enough and A is not `changing`: forming H
/// takes m solves, m more at each change of A. A run that solves the
/// contact once would pay the Schur complement for one solve: there the
/// whole system's first Newton steps come first, all a solve whose active
/// set they find costs; else the condensed path follows. Throws
/// OptionsError for a value that is not a boolean, or a -snes_type of
/// either prefix (<prefix>, <prefix>contact_) that takes no bounds
/// (collective).
ContactPathChoice choose_contact_path(MPI_Comm comm, const std::string& prefix, const PathCosts& costs);

} // namespace biotcontact
