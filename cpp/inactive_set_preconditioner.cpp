#include "inactive_set_preconditioner.h"

#include "solver.h"

namespace biotcontact
{

InactiveSetPreconditioner::InactiveSetPreconditioner(SNES snes, Mat A, const std::string& prefix)
    : _snes(snes), _A(A)
{
  KSP ksp;
  SNESGetKSP(snes, &ksp);
  PC pc;
  KSPGetPC(ksp, &pc);
  // Its own prefix: SNES VI resets the reduced KSP from the options at every
  // change of the inactive set, and -<prefix>pc_type names the inner AMG.
  PCSetOptionsPrefix(pc, (prefix + "inactive_").c_str());
  set_default_option(prefix + "inactive_pc_type", "shell");
  PCSetType(pc, PCSHELL);
  PCShellSetContext(pc, this);
  PCShellSetSetUp(pc, &InactiveSetPreconditioner::set_up);
  PCShellSetApply(pc, &InactiveSetPreconditioner::apply);
  PCShellSetName(pc, "AMG on A with the active DOFs held (inactive_set_preconditioner.h)");

  // The inner AMG on A_D: A's block size and near-nullspace come with the
  // duplicate; reuse of the prolongators across active sets by default.
  set_default_option(prefix + "pc_gamg_reuse_interpolation", "true");
  MatDuplicate(A, MAT_COPY_VALUES, &_A_D);
  MatNullSpace modes = nullptr;
  MatGetNearNullSpace(A, &modes);
  if (modes)
    MatSetNearNullSpace(_A_D, modes);
  PCCreate(PetscObjectComm(reinterpret_cast<PetscObject>(A)), &_amg);
  PCSetOptionsPrefix(_amg, prefix.c_str());
  PCSetOperators(_amg, _A_D, _A_D);
  PCSetFromOptions(_amg);
  MatCreateVecs(A, &_r_full, &_y_full);
}

InactiveSetPreconditioner::~InactiveSetPreconditioner()
{
  PCDestroy(&_amg);
  MatDestroy(&_A_D);
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

  // A_D: A with the active rows and columns made identity rows.
  PetscInt start = 0, end = 0;
  PetscCall(MatGetOwnershipRange(self->_A, &start, &end));
  IS active = nullptr;
  PetscCall(ISComplement(inactive, start, end, &active));
  PetscCall(MatCopy(self->_A, self->_A_D, SAME_NONZERO_PATTERN));
  PetscCall(MatZeroRowsColumnsIS(self->_A_D, active, 1.0, nullptr, nullptr));
  PetscCall(ISDestroy(&active));
  PetscCall(PCSetOperators(self->_amg, self->_A_D, self->_A_D));
  PetscCall(PCSetUp(self->_amg));
  ++self->setups;
  self->setup_time += MPI_Wtime() - started;
  return 0;
}

PetscErrorCode InactiveSetPreconditioner::apply(PC pc, Vec r, Vec y)
{
  InactiveSetPreconditioner* self = nullptr;
  PetscCall(PCShellGetContext(pc, &self));
  // y_I = R_I AMG(A_D)^-1 R_I^T r_I; the active entries of r are zero.
  PetscCall(VecSet(self->_r_full, 0.0));
  PetscCall(VecISCopy(self->_r_full, self->_inactive, SCATTER_FORWARD, r));
  PetscCall(PCApply(self->_amg, self->_r_full, self->_y_full));
  PetscCall(VecISCopy(self->_y_full, self->_inactive, SCATTER_REVERSE, y));
  return 0;
}

} // namespace biotcontact
