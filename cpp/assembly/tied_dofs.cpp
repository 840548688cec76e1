#include "assembly/tied_dofs.h"

#include <mpi.h>

namespace biotcontact
{

TiedDofs::TiedDofs(Mat A, const std::vector<Tie>& ties)
{
  MPI_Comm comm = PetscObjectComm(reinterpret_cast<PetscObject>(A));
  PetscInt m = 0, n = 0, start = 0, end = 0;
  MatGetLocalSize(A, &m, &n);
  MatGetOwnershipRange(A, &start, &end);
  // Row j of P holds 1 at j and s at i (i possibly off this rank).
  MatCreateAIJ(comm, m, n, PETSC_DETERMINE, PETSC_DETERMINE, 2, nullptr, 1, nullptr, &_P);
  for (PetscInt r = start; r < end; ++r)
    MatSetValue(_P, r, r, 1.0, INSERT_VALUES);
  for (const Tie& t : ties)
  {
    MatSetValue(_P, t.j, t.i, t.s, INSERT_VALUES);
    _j.push_back(t.j);
  }
  MatAssemblyBegin(_P, MAT_FINAL_ASSEMBLY);
  MatAssemblyEnd(_P, MAT_FINAL_ASSEMBLY);
  PetscInt local = static_cast<PetscInt>(_j.size());
  MPI_Allreduce(&local, &_size, 1, MPIU_INT, MPI_SUM, comm);
}

TiedDofs::~TiedDofs() { MatDestroy(&_P); }

void TiedDofs::reduce(Mat A, Mat* At) const
{
  MatPtAP(A, _P, *At ? MAT_REUSE_MATRIX : MAT_INITIAL_MATRIX, PETSC_DEFAULT, At);
  MatZeroRowsColumns(*At, static_cast<PetscInt>(_j.size()), _j.data(), 1.0, nullptr, nullptr);
}

void TiedDofs::load(Vec b, Vec bt) const
{
  MatMultTranspose(_P, b, bt);
  for (PetscInt j : _j)
    VecSetValue(bt, j, 0.0, INSERT_VALUES);
  VecAssemblyBegin(bt);
  VecAssemblyEnd(bt);
}

void TiedDofs::guess(Vec x, Vec y) const
{
  VecCopy(x, y);
  for (PetscInt j : _j)
    VecSetValue(y, j, 0.0, INSERT_VALUES);
  VecAssemblyBegin(y);
  VecAssemblyEnd(y);
}

void TiedDofs::expand(Vec y, Vec x) const { MatMult(_P, y, x); }

} // namespace biotcontact
