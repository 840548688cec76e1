#include "assembly/tied_dofs.h"

#include "assembly/petsc_error.h"

#include <mpi.h>

namespace biotcontact
{

TiedDofs::TiedDofs(Mat A, const std::vector<Tie>& ties)
{
  MPI_Comm comm = PetscObjectComm(reinterpret_cast<PetscObject>(A));
  PetscInt m = 0, n = 0, start = 0, end = 0;
  check_petsc(MatGetLocalSize(A, &m, &n), "the tied DOFs: MatGetLocalSize");
  check_petsc(MatGetOwnershipRange(A, &start, &end), "the tied DOFs: MatGetOwnershipRange");
  // Row j of P holds 1 at j and s at i (i possibly off this rank).
  check_petsc(MatCreateAIJ(comm, m, n, PETSC_DETERMINE, PETSC_DETERMINE, 2, nullptr, 1, nullptr, &_P),
              "the tied DOFs: MatCreateAIJ of P");
  for (PetscInt r = start; r < end; ++r)
    check_petsc(MatSetValue(_P, r, r, 1.0, INSERT_VALUES), "the tied DOFs: MatSetValue of P");
  for (const Tie& t : ties)
  {
    check_petsc(MatSetValue(_P, t.j, t.i, t.s, INSERT_VALUES), "the tied DOFs: MatSetValue of P");
    _j.push_back(t.j);
  }
  check_petsc(MatAssemblyBegin(_P, MAT_FINAL_ASSEMBLY), "the tied DOFs: MatAssemblyBegin of P");
  check_petsc(MatAssemblyEnd(_P, MAT_FINAL_ASSEMBLY), "the tied DOFs: MatAssemblyEnd of P");
  PetscInt local = static_cast<PetscInt>(_j.size());
  MPI_Allreduce(&local, &_size, 1, MPIU_INT, MPI_SUM, comm);
}

TiedDofs::~TiedDofs() { warn_petsc(MatDestroy(&_P), "the tied DOFs: MatDestroy of P"); }

void TiedDofs::reduce(Mat A, Mat* At) const
{
  check_petsc(MatPtAP(A, _P, *At ? MAT_REUSE_MATRIX : MAT_INITIAL_MATRIX, PETSC_DEFAULT, At),
              "the tied DOFs: MatPtAP");
  check_petsc(MatZeroRowsColumns(*At, static_cast<PetscInt>(_j.size()), _j.data(), 1.0, nullptr, nullptr),
              "the tied DOFs: MatZeroRowsColumns");
}

void TiedDofs::load(Vec b, Vec bt) const
{
  check_petsc(MatMultTranspose(_P, b, bt), "the tied DOFs' load: MatMultTranspose");
  for (PetscInt j : _j)
    check_petsc(VecSetValue(bt, j, 0.0, INSERT_VALUES), "the tied DOFs' load: VecSetValue");
  check_petsc(VecAssemblyBegin(bt), "the tied DOFs' load: VecAssemblyBegin");
  check_petsc(VecAssemblyEnd(bt), "the tied DOFs' load: VecAssemblyEnd");
}

void TiedDofs::guess(Vec x, Vec y) const
{
  check_petsc(VecCopy(x, y), "the tied DOFs' guess: VecCopy");
  for (PetscInt j : _j)
    check_petsc(VecSetValue(y, j, 0.0, INSERT_VALUES), "the tied DOFs' guess: VecSetValue");
  check_petsc(VecAssemblyBegin(y), "the tied DOFs' guess: VecAssemblyBegin");
  check_petsc(VecAssemblyEnd(y), "the tied DOFs' guess: VecAssemblyEnd");
}

void TiedDofs::expand(Vec y, Vec x) const
{
  check_petsc(MatMult(_P, y, x), "the tied DOFs' expansion x = P y: MatMult");
}

} // namespace biotcontact
