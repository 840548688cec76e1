#include "solvers/inactive_set_preconditioner.h"

#include "solvers/solver.h"

namespace biotcontact
{

InactiveSetPreconditioner::InactiveSetPreconditioner(SNES snes, Mat P, const std::vector<Field>& fields,
                                                     Vec row_weights, const std::string& prefix)
    : _snes(snes), _P(P), _row_weights(row_weights)
{
  auto check = [&prefix](PetscErrorCode code, const char* call)
  {
    if (code != 0)
      check_petsc(code, "the inactive-set preconditioner of " + system_name(prefix) + ": " + call);
  };
  KSP ksp;
  check(SNESGetKSP(snes, &ksp), "SNESGetKSP");
  PC pc;
  check(KSPGetPC(ksp, &pc), "KSPGetPC");
  // Its own prefix: SNES VI resets the reduced KSP from the options at every
  // change of the inactive set, and -<prefix>pc_type names the inner
  // preconditioner.
  check(PCSetOptionsPrefix(pc, (prefix + "inactive_").c_str()), "PCSetOptionsPrefix");
  set_default_option(prefix + "inactive_pc_type", "shell");
  check(PCSetType(pc, PCSHELL), "PCSetType");
  check(PCShellSetContext(pc, this), "PCShellSetContext");
  check(PCShellSetSetUp(pc, &InactiveSetPreconditioner::set_up), "PCShellSetSetUp");
  check(PCShellSetApply(pc, &InactiveSetPreconditioner::apply), "PCShellSetApply");
  check(PCShellSetName(pc, "the system's preconditioner on P with the active DOFs held "
                           "(inactive_set_preconditioner.h)"),
        "PCShellSetName");

  // The inner preconditioner on P_D: P's block size and near-nullspace come
  // with the duplicate, its fields with set_fields; GAMG (of the mechanics,
  // or of the displacement field of the coupled system) reuses its
  // prolongators across active sets by default (solver.cpp).
  check(MatDuplicate(P, MAT_COPY_VALUES, &_P_D), "MatDuplicate of P");
  MatNullSpace modes = nullptr;
  check(MatGetNearNullSpace(P, &modes), "MatGetNearNullSpace of P");
  if (modes)
    check(MatSetNearNullSpace(_P_D, modes), "MatSetNearNullSpace");
  check(PCCreate(PetscObjectComm(reinterpret_cast<PetscObject>(P)), &_inner), "PCCreate");
  check(PCSetOptionsPrefix(_inner, prefix.c_str()), "PCSetOptionsPrefix of the inner PC");
  check(PCSetOperators(_inner, _P_D, _P_D), "PCSetOperators");
  check(PCSetFromOptions(_inner), "PCSetFromOptions of the inner PC");
  set_fields(_inner, fields, prefix);
  check(MatCreateVecs(P, &_r_full, &_y_full), "MatCreateVecs");
}

InactiveSetPreconditioner::~InactiveSetPreconditioner()
{
  warn_petsc(PCDestroy(&_inner), "the inactive-set preconditioner: PCDestroy");
  warn_petsc(MatDestroy(&_P_D), "the inactive-set preconditioner: MatDestroy");
  warn_petsc(ISDestroy(&_inactive), "the inactive-set preconditioner: ISDestroy");
  warn_petsc(VecDestroy(&_r_full), "the inactive-set preconditioner: VecDestroy");
  warn_petsc(VecDestroy(&_y_full), "the inactive-set preconditioner: VecDestroy");
}

PetscErrorCode InactiveSetPreconditioner::set_up(PC pc)
{
  InactiveSetPreconditioner* self = nullptr;
  PetscCall(PCShellGetContext(pc, &self));
  const double started = MPI_Wtime();
  // The inactive set of this Newton step (valid while SNES VI sets up and
  // solves the reduced system); kept, since SNES destroys its own copy
  // after the step while the set-up is reused for as long as the set is
  // unchanged.
  IS inactive = nullptr;
  PetscCall(SNESVIGetInactiveSet(self->_snes, &inactive));
  PetscCall(PetscObjectReference(reinterpret_cast<PetscObject>(inactive)));
  PetscCall(ISDestroy(&self->_inactive));
  self->_inactive = inactive;

  // P_D: P with the active rows and columns made identity rows.
  PetscInt start = 0, end = 0;
  PetscCall(MatGetOwnershipRange(self->_P, &start, &end));
  IS active = nullptr;
  PetscCall(ISComplement(inactive, start, end, &active));
  PetscCall(MatCopy(self->_P, self->_P_D, SAME_NONZERO_PATTERN));
  if (self->_row_weights)
    PetscCall(MatDiagonalScale(self->_P_D, self->_row_weights, nullptr));
  PetscCall(MatZeroRowsColumnsIS(self->_P_D, active, 1.0, nullptr, nullptr));
  PetscCall(ISDestroy(&active));
  PetscCall(PCSetOperators(self->_inner, self->_P_D, self->_P_D));
  PetscCall(PCSetUp(self->_inner));
  ++self->setups;
  self->setup_time += MPI_Wtime() - started;
  return 0;
}

PetscErrorCode InactiveSetPreconditioner::apply(PC pc, Vec r, Vec y)
{
  InactiveSetPreconditioner* self = nullptr;
  PetscCall(PCShellGetContext(pc, &self));
  // y_I = R_I B(P_D)^-1 R_I^T r_I; the active entries of r are zero.
  PetscCall(VecSet(self->_r_full, 0.0));
  PetscCall(VecISCopy(self->_r_full, self->_inactive, SCATTER_FORWARD, r));
  PetscCall(PCApply(self->_inner, self->_r_full, self->_y_full));
  PetscCall(VecISCopy(self->_y_full, self->_inactive, SCATTER_REVERSE, y));
  return 0;
}

} // namespace biotcontact
