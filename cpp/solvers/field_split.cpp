#include "solvers/field_split.h"

#include "assembly/petsc_error.h"
#include "solvers/options.h"

#include <algorithm>

namespace biotcontact
{

bool is_coupled(const std::vector<Field>& fields)
{
  return std::any_of(fields.begin(), fields.end(), [](const Field& f) { return !f.fields.empty(); });
}

std::shared_ptr<std::remove_pointer_t<MatNullSpace>> own(MatNullSpace space)
{
  return {space, [](MatNullSpace s) { warn_petsc(MatNullSpaceDestroy(&s), "a near-nullspace: MatNullSpaceDestroy"); }};
}

PetscInt block_offset(const Field& whole, MPI_Comm comm)
{
  PetscInt local = static_cast<PetscInt>(whole.dofs.size()), offset = 0;
  MPI_Exscan(&local, &offset, 1, MPIU_INT, MPI_SUM, comm);
  int rank = 0;
  MPI_Comm_rank(comm, &rank);
  return rank == 0 ? 0 : offset; // MPI_Exscan leaves rank 0's result undefined
}

Field part_of(const Field& whole, const std::string& name, const std::vector<PetscInt>& dofs, MPI_Comm comm)
{
  const PetscInt offset = block_offset(whole, comm);
  Field part{name, {}};
  part.dofs.reserve(dofs.size());
  for (PetscInt dof : dofs)
  {
    auto it = std::lower_bound(whole.dofs.begin(), whole.dofs.end(), dof);
    if (it == whole.dofs.end() or *it != dof)
      throw std::logic_error("field " + name + " is not a part of field " + whole.name);
    part.dofs.push_back(offset + static_cast<PetscInt>(it - whole.dofs.begin()));
  }
  return part;
}

namespace
{
bool is_field_split(PC pc)
{
  PetscBool split = PETSC_FALSE;
  check_petsc(PetscObjectTypeCompare(reinterpret_cast<PetscObject>(pc), PCFIELDSPLIT, &split),
              "a preconditioner: PetscObjectTypeCompare");
  return split;
}

/// check_petsc with "<the system> field split: <call>", the text built only
/// when the call failed.
void check_split(PetscErrorCode code, const std::string& prefix, const char* call)
{
  if (code != 0)
    check_petsc(code, system_name(prefix) + " field split: " + call);
}
} // namespace

void set_fields(PC pc, const std::vector<Field>& fields, const std::string& prefix)
{
  if (!is_field_split(pc))
    return;
  if (fields.empty())
    throw OptionsError("-" + prefix + "pc_type fieldsplit: " + system_name(prefix) + " system has no fields to split");
  IS given = nullptr;
  check_split(PCFieldSplitGetIS(pc, fields.front().name.c_str(), &given), prefix, "PCFieldSplitGetIS");
  if (given)
    return; // already split (a preconditioner set up again)
  const MPI_Comm comm = PetscObjectComm(reinterpret_cast<PetscObject>(pc));
  for (const Field& f : fields)
  {
    IS is;
    check_split(ISCreateGeneral(comm, static_cast<PetscInt>(f.dofs.size()), f.dofs.data(), PETSC_COPY_VALUES, &is),
                prefix, "ISCreateGeneral");
    // The block of the field inherits the index set's block size (MatCreateSubMatrix),
    // and PCFieldSplit gives it the near-nullspace composed here.
    check_split(ISSetBlockSize(is, f.block_size), prefix, "ISSetBlockSize");
    if (f.near_nullspace)
      check_split(PetscObjectCompose(reinterpret_cast<PetscObject>(is), "nearnullspace",
                                     reinterpret_cast<PetscObject>(f.near_nullspace.get())),
                  prefix, "PetscObjectCompose of a near-nullspace");
    check_split(PCFieldSplitSetIS(pc, f.name.c_str(), is), prefix, "PCFieldSplitSetIS");
    check_split(ISDestroy(&is), prefix, "ISDestroy");
  }
  if (!is_coupled(fields))
    return;
  KSP* sub = nullptr;
  PetscInt n = 0;
  check_split(PCFieldSplitGetSubKSP(pc, &n, &sub), prefix, "PCFieldSplitGetSubKSP");
  for (PetscInt i = 0; i < n; ++i)
  {
    if (fields[i].fields.empty())
      continue;
    // The sub-solver exists from PCFieldSplitSetIS on, with the prefix
    // <prefix>fieldsplit_<name>_: its type is read now, so that its own
    // splits are in place before the outer set-up.
    const char* sub_prefix = nullptr;
    check_split(KSPGetOptionsPrefix(sub[i], &sub_prefix), prefix, "KSPGetOptionsPrefix of a field");
    // Bad input, as in LinearSolver's constructor: the field's own options make no solver.
    if (const PetscErrorCode ierr = KSPSetFromOptions(sub[i]); ierr != 0)
      throw OptionsError("the PETSc options of " + system_name(sub_prefix ? sub_prefix : prefix)
                         + " solver do not make a solver: " + petsc_error_text(ierr));
    PC sub_pc;
    check_split(KSPGetPC(sub[i], &sub_pc), prefix, "KSPGetPC of a field");
    set_fields(sub_pc, fields[i].fields, sub_prefix ? sub_prefix : prefix);
  }
  check_split(PetscFree(sub), prefix, "PetscFree of the fields' solvers");
}

} // namespace biotcontact
