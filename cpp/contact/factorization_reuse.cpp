#include "contact/factorization_reuse.h"

#include "assembly/petsc_error.h"
#include "solvers/solver.h"

namespace biotcontact
{

std::vector<std::pair<std::string, std::string>> reuse_options(const std::string& prefix)
{
  std::vector<std::pair<std::string, std::string>> options;
  for (const auto& [name, value] : {std::pair<std::string, std::string>{"ksp_type", "gmres"},
                                    {"ksp_rtol", "1e-12"},
                                    {"ksp_max_it", "100"}})
    if (!given_by_user(prefix + name))
      options.emplace_back(prefix + name, value);
  return options;
}

void analyse_quickly(const std::string& prefix, Mat K)
{
  PetscInt rows = 0;
  check_petsc(MatGetSize(K, &rows, nullptr), "contact solver: MatGetSize");
  if (rows > quick_analysis_rows)
    return;
  const std::string factor = factor_prefix(prefix);
  if (option(factor, "-pc_factor_mat_solver_type") == "mumps")
    set_default_option(factor + "mat_mumps_icntl_7", "0");
}

KrylovOnReuse::KrylovOnReuse(SNES snes, const std::vector<std::pair<std::string, std::string>>& options)
{
  for (const auto& [name, value] : options)
  {
    _before.emplace_back(name, option("", ("-" + name).c_str()));
    check_petsc(PetscOptionsSetValue(nullptr, ("-" + name).c_str(), value.c_str()),
                "contact solver: PetscOptionsSetValue -" + name);
  }
  KSP ksp;
  check_petsc(SNESGetKSP(snes, &ksp), "contact solver: SNESGetKSP");
  check_petsc(KSPSetFromOptions(ksp), "contact solver: KSPSetFromOptions");
}

KrylovOnReuse::~KrylovOnReuse()
{
  for (const auto& [name, value] : _before)
    warn_petsc(value.empty() ? PetscOptionsClearValue(nullptr, ("-" + name).c_str())
                             : PetscOptionsSetValue(nullptr, ("-" + name).c_str(), value.c_str()),
               "contact solver: restoring a PETSc option");
}

} // namespace biotcontact
