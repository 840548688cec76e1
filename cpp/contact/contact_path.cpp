#include "contact/contact_path.h"

#include "solvers/options.h"

#include <petscoptions.h>
#include <petscsnes.h>

namespace biotcontact
{
namespace
{
/// Reads -<prefix>contact_condensed; `given` says whether the user set it.
/// PetscOptionsBegin/End spelled out (PETSc 3.18's petscoptions.h), so that
/// every code is checked where it is made; PetscOptionsBool expects the
/// items under the name PetscOptionsObject.
PetscErrorCode read_condensed(MPI_Comm comm, const std::string& prefix, PetscBool fallback, PetscBool* condensed,
                              PetscBool* given)
{
  PetscFunctionBeginUser;
  const std::string text = "pose the contact VI on the Schur complement of the contact DOFs (default with a "
                           "direct solver and at most "
                           + std::to_string(max_condensed_dofs)
                           + " contact DOFs, after one full Newton step, two with friction, that did not "
                             "converge when the run solves the contact once), else on the whole system";
  PetscOptionItems items{};
  PetscOptionItems* PetscOptionsObject = &items;
  for (items.count = PetscOptionsPublish ? -1 : 1; items.count < 2; ++items.count)
  {
    PetscCall(PetscOptionsBegin_Private(PetscOptionsObject, comm, prefix.c_str(), "Contact solver (biotcontact)",
                                        nullptr));
    PetscCall(PetscOptionsBool("-contact_condensed", text.c_str(), "docs/user-guide.md", fallback, condensed, given));
    PetscCall(PetscOptionsEnd_Private(PetscOptionsObject));
  }
  PetscFunctionReturn(0);
}

/// Only the VI methods take bounds; any other would ignore the contact.
/// Asked of both prefixes, so that a type given for the path not taken is
/// not ignored silently either. An iterative `method` preconditions the
/// reduced-space steps on their inactive set (InactiveSetPreconditioner),
/// which vinewtonssls, stepping on the whole space, does not have.
void check_bound_method(const std::string& prefix, Method method)
{
  for (const std::string& p : {prefix, prefix + "contact_"})
  {
    const std::string type = option(p, "-snes_type");
    if (!type.empty() and type != SNESVINEWTONRSLS and type != SNESVINEWTONSSLS)
      throw OptionsError("-" + p + "snes_type " + type
                         + ": the contact solver needs a bound-constrained method (vinewtonrsls or vinewtonssls)");
    // nleqerr failed on the reduced space ("Incompatible vector local
    // lengths", PETSc error 60, at the first Newton step).
    const std::string search = option(p, "-snes_linesearch_type");
    if (!search.empty() and search != "basic" and search != "bt" and search != "l2" and search != "cp")
      throw OptionsError("-" + p + "snes_linesearch_type " + search
                         + ": the contact solver takes the line searches basic, bt, l2 or cp");
  }
  if (method == Method::iterative and option(prefix, "-snes_type") == SNESVINEWTONSSLS)
    throw OptionsError("-" + prefix + "snes_type vinewtonssls: the iterative contact solver needs vinewtonrsls "
                       "(its preconditioner works on the reduced space's inactive set); vinewtonssls needs the "
                       "direct solver");
}
} // namespace

ContactPathChoice choose_contact_path(MPI_Comm comm, const std::string& prefix, const PathCosts& costs)
{
  check_bound_method(prefix, costs.method);
  // Forming H takes m solves: cheap back-solves of a factorisation, but m
  // full Krylov solves with an iterative method, and m more at each change
  // of A.
  const bool open = costs.method == Method::direct and costs.contact_dofs <= max_condensed_dofs;
  PetscBool condensed = open and !costs.changing ? PETSC_TRUE : PETSC_FALSE, given = PETSC_FALSE;
  if (read_condensed(comm, prefix, condensed, &condensed, &given) != 0)
    throw OptionsError("-" + prefix + "contact_condensed: not a boolean (true or false)");
  if (!condensed)
    return {ContactPath::full, open and !given};
  return {costs.once and !given ? ContactPath::full_then_condensed : ContactPath::condensed, false};
}

} // namespace biotcontact
