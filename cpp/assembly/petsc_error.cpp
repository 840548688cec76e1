#include "assembly/petsc_error.h"

#include <cstdio>

namespace biotcontact
{

std::string petsc_error_text(PetscErrorCode code)
{
  const char* text = nullptr;
  char* specific = nullptr;
  std::string words;
  if (PetscErrorMessage(code, &text, &specific) == 0)
    words = specific and *specific ? specific : (text ? text : "");
  // PETSc's messages may end in a newline or a period; one line is kept.
  words = words.substr(0, words.find('\n'));
  while (!words.empty() and (words.back() == '.' or words.back() == ' '))
    words.pop_back();
  const std::string number = "PETSc error " + std::to_string(code);
  return words.empty() ? number : words + " (" + number + ")";
}

void check_petsc(PetscErrorCode code, std::string_view what)
{
  if (code != 0)
    throw SolverError(std::string(what) + ": " + petsc_error_text(code));
}

void check_petsc(PetscErrorCode code, const char* context, const char* call)
{
  if (code != 0)
    check_petsc(code, std::string(context) + ": " + call);
}

PetscErrorCode agreed_code(PetscErrorCode code, MPI_Comm comm)
{
  int mine = static_cast<int>(code), largest = 0;
  check_petsc(MPI_Allreduce(&mine, &largest, 1, MPI_INT, MPI_MAX, comm) == MPI_SUCCESS ? 0 : PETSC_ERR_MPI,
              "agreeing on a PETSc error code: MPI_Allreduce");
  return static_cast<PetscErrorCode>(largest);
}

void warn_petsc(PetscErrorCode code, const char* what) noexcept
{
  if (code != 0)
    std::fprintf(stderr, "biotcontact: warning: %s: PETSc error %d\n", what, static_cast<int>(code));
}

} // namespace biotcontact
