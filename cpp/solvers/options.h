// The project's PETSc options as the solvers read them: the error that
// options which do not make a solver raise, the name of a system in
// messages, from its options prefix, and the packages refused. Below
// solver.h and field_split.h, which both report bad options.
#pragma once

#include <stdexcept>
#include <string>

namespace biotcontact
{

/// PETSc options that do not make a solver: bad input (exit 2).
struct OptionsError : std::runtime_error
{
  using std::runtime_error::runtime_error;
};

/// "the mechanics" from "mechanics_".
std::string system_name(const std::string& prefix);

/// The error for PETSc options (`options`: "-name value ..." as
/// PetscOptionsGetAll gives them) that name SuperLU_DIST while OpenMP runs
/// `threads` threads per process; "" when none does or there is one thread.
/// Debian's SuperLU_DIST 8.1.2 solves wrongly with more than one: on the
/// default scene the contact solver cycles and the split diverges
/// (docs/performance.md, "thirty-third session").
std::string threaded_superlu(const std::string& options, int threads);

/// The error for a relative tolerance (-<prefix>ksp_rtol, -<prefix>snes_rtol)
/// in `options` outside [0, 1): from 1 on, any first iterate meets it (a
/// Hertz contact 147 times off with exit 0); "" when there is none.
std::string relative_tolerance_out_of_range(const std::string& options);

} // namespace biotcontact
