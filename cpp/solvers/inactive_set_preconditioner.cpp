#include "solvers/inactive_set_preconditioner.h"

#include "solvers/solver.h"

namespace biotcontact
{

InactiveSetPreconditioner::InactiveSetPreconditioner(SNES snes, Mat P, const std::vector<Field>& fields,
                                                     const std::string& prefix)
    : _snes(snes), _P(P)
{
  KSP ksp;
  SNESGetKSP(snes, &ksp);
  PC pc;
  KSPGetPC(ksp, &pc);
  // Its own prefix: SNES VI resets the reduced KSP from the options at every
  // change of the inactive set, and -<prefix>pc_type names the inner
  // preconditioner.
  PCSetOptionsPrefix(pc, (prefix + "inactive_").c_str());
  set_default_option(prefix + "inactive_pc_type", "shell");
  PCSetType(pc, PCSHELL);
  PCShellSetContext(pc, this);
  PCShellSetSetUp(pc, &InactiveSetPreconditioner::set_up);
  PCShellSetApply(pc, &InactiveSetPreconditioner::apply);
  PCShellSetName(pc, "the system's preconditioner on P with the active DOFs held (inactive_set_preconditioner.h)");

  // The inner preconditioner on P_D: P's block size and near-nullspace come
  // with the duplicate, its fields with set_fields; GAMG (of the mechanics,
  // or of the displacement field of the coupled system) reuses its
  // prolongators across active sets by default (solver.cpp).
  MatDuplicate(P, MAT_COPY_VALUES, &_P_D);
  MatNullSpace modes = nullptr;
  MatGetNearNullSpace(P, &modes);
  if (modes)
    MatSetNearNullSpace(_P_D, modes);
  PCCreate(PetscObjectComm(reinterpret_cast<PetscObject>(P)), &_inner);
  PCSetOptionsPrefix(_inner, prefix.c_str());
  PCSetOperators(_inner, _P_D, _P_D);
  PCSetFromOptions(_inner);
  set_fields(_inner, fields, prefix);
  MatCreateVecs(P, &_r_full, &_y_full);
}

InactiveSetPreconditioner::~InactiveSetPreconditioner()
{
  PCDestroy(&_inner);
  MatDestroy(&_P_D);
  ISDestroy(&_inactive);
  VecDestroy(&_r_full);
  VecDestroy(&_y_full);
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
