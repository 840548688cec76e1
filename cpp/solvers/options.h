// The project's PETSc options as the solvers read them: the error that
// options which do not make a solver raise, and the name of a system in
// messages, from its options prefix. Below solver.h and field_split.h,
// which both report bad options.
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

} // namespace biotcontact
