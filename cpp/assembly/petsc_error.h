// PETSc's error codes, checked: main.cpp makes PETSc return its codes
// instead of aborting, so every call's code goes through check_petsc,
// PetscCall (in PETSc's callbacks) or warn_petsc (tests/test_petsc_checked.py).
// Here, in the lowest layer that calls PETSc, so that every layer may use them.
#pragma once

#include <petscsys.h>
#include <stdexcept>
#include <string>
#include <string_view>

namespace biotcontact
{

/// A solver that did not converge, or a PETSc call that failed
/// (check_petsc): the run stops with this message.
struct SolverError : std::runtime_error
{
  using std::runtime_error::runtime_error;
};

/// PETSc's own words for the error a call just returned, e.g. "Unknown PC
/// type: nonsense (PETSc error 86)": the first message of the failing
/// call's chain, which PETSc keeps though main.cpp's handler prints nothing.
std::string petsc_error_text(PetscErrorCode code);

/// Throws SolverError "<what>: <petsc_error_text>" when a PETSc call failed.
/// A string literal as `what` costs nothing when the call succeeded.
void check_petsc(PetscErrorCode code, std::string_view what);

/// check_petsc with "<context>: <call>", the text built only when the call
/// failed (for calls made once per entry or cell).
void check_petsc(PetscErrorCode code, const char* context, const char* call);

/// The code of a call that every rank of `comm` made, as every rank sees
/// it: the largest of the ranks' codes, 0 where all succeeded. Where a
/// failure may be one rank's alone (a factorisation each rank does on its
/// own copy, PCREDUNDANT) and decides what follows (another package, the
/// error), every rank then takes the same path, instead of one waiting for
/// the others in a collective they never reach (collective).
PetscErrorCode agreed_code(PetscErrorCode code, MPI_Comm comm);

/// For destructors, which cannot throw: one warning line on stderr when a
/// PETSc call failed (a release that failed leaks, it corrupts nothing).
void warn_petsc(PetscErrorCode code, const char* what) noexcept;

} // namespace biotcontact
