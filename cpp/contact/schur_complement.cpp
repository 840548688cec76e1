#include "contact/schur_complement.h"

#include <algorithm>
#include <dolfinx/common/Timer.h>

namespace biotcontact
{

SchurComplement::SchurComplement(MPI_Comm comm, const std::string& prefix, Mat A, Structure structure,
                                 std::vector<std::int32_t> dofs)
    : _comm(comm), _prefix(prefix), _A(A), _structure(structure), _dofs(std::move(dofs))
{
  int ranks = 1;
  MPI_Comm_size(comm, &ranks);
  const int local = static_cast<int>(_dofs.size());
  _counts.resize(ranks);
  MPI_Allgather(&local, 1, MPI_INT, _counts.data(), 1, MPI_INT, comm);
  _displacements.resize(ranks);
  int rank = 0;
  MPI_Comm_rank(comm, &rank);
  for (int r = 0, sum = 0; r < ranks; sum += _counts[r], ++r)
    _displacements[r] = sum;
  _offset = _displacements[rank];
  _m = _displacements.back() + _counts.back();
  MatGetOwnershipRange(A, &_first_row, nullptr);
  MatCreateVecs(A, &_v, &_w);
  MatCreateSeqDense(PETSC_COMM_SELF, _m, _m, nullptr, &_H);
}

SchurComplement::~SchurComplement()
{
  _solver.reset();
  MatDestroy(&_clamped);
  MatDestroy(&_H);
  VecDestroy(&_v);
  VecDestroy(&_w);
}

void SchurComplement::gather(const PetscScalar* local, PetscScalar* all) const
{
  MPI_Allgatherv(local, static_cast<int>(_dofs.size()), MPI_DOUBLE, all,
                 _counts.data(), _displacements.data(), MPI_DOUBLE, _comm);
}

void SchurComplement::assemble()
{
  // A_C: the contact DOFs clamped (identity rows and columns). Its
  // factorisation is the system's one (same options prefix, same log stage).
  _solver.reset();
  MatDestroy(&_clamped);
  MatDuplicate(_A, MAT_COPY_VALUES, &_clamped);
  std::vector<PetscInt> rows(_dofs.size());
  std::transform(_dofs.begin(), _dofs.end(), rows.begin(), [&](std::int32_t d) { return _first_row + d; });
  MatZeroRowsColumns(_clamped, static_cast<PetscInt>(rows.size()), rows.data(), 1.0, nullptr, nullptr);
  _solver = std::make_unique<LinearSolver>(_comm, _prefix, _clamped, _clamped, _structure);
  _solver->set_up();

  dolfinx::common::Timer timer("Schur complement");

  // Blocks of right-hand sides: one call into the factorisation each, with
  // the dense blocks (n x block) kept to a few tens of megabytes.
  PetscInt n = 0;
  MatGetSize(_A, &n, nullptr);
  const PetscInt block = std::clamp<PetscInt>(static_cast<PetscInt>(4e6 / std::max<PetscInt>(n, 1)), 1, 64);
  for (PetscInt first = 0; first < _m; first += block)
    form_columns(first, std::min(block, _m - first));
  columns += _m;
  time += timer.stop();
}

void SchurComplement::form_columns(PetscInt first, PetscInt count)
{
  // Column j of H is (A E_j)_C with E_j = e_j - A_C^{-1} (A e_j)|_I: the
  // unit displacement of contact DOF j, extended to I by the equations of
  // I with the other contact DOFs held at zero.
  PetscInt n_local = 0;
  MatGetLocalSize(_A, &n_local, nullptr);
  Mat E, R, X, AE;
  MatCreateDense(_comm, n_local, PETSC_DECIDE, PETSC_DETERMINE, count, nullptr, &E);
  for (std::size_t k = 0; k < _dofs.size(); ++k)
    if (const PetscInt j = _offset + static_cast<PetscInt>(k); j >= first and j < first + count)
      MatSetValue(E, _first_row + _dofs[k], j - first, 1.0, INSERT_VALUES);
  MatAssemblyBegin(E, MAT_FINAL_ASSEMBLY);
  MatAssemblyEnd(E, MAT_FINAL_ASSEMBLY);

  // R = (A e_j) with the rows of C zeroed; X = A_C^{-1} R vanishes on C.
  MatMatMult(_A, E, MAT_INITIAL_MATRIX, PETSC_DEFAULT, &R);
  {
    PetscScalar* r = nullptr;
    PetscInt lda = 0;
    MatDenseGetLDA(R, &lda);
    MatDenseGetArray(R, &r);
    for (PetscInt c = 0; c < count; ++c)
      for (std::int32_t d : _dofs)
        r[d + c * lda] = 0;
    MatDenseRestoreArray(R, &r);
  }
  MatDuplicate(R, MAT_DO_NOT_COPY_VALUES, &X);
  _solver->solve(X, R);
  MatAXPY(E, -1.0, X, SAME_NONZERO_PATTERN);
  MatMatMult(_A, E, MAT_INITIAL_MATRIX, PETSC_DEFAULT, &AE);

  const PetscScalar* ae = nullptr;
  PetscInt lda = 0;
  MatDenseGetLDA(AE, &lda);
  MatDenseGetArrayRead(AE, &ae);
  PetscScalar* h = nullptr;
  MatDenseGetArray(_H, &h); // column-major, leading dimension m
  std::vector<PetscScalar> local(_dofs.size());
  for (PetscInt c = 0; c < count; ++c)
  {
    for (std::size_t k = 0; k < _dofs.size(); ++k)
      local[k] = ae[_dofs[k] + c * lda];
    gather(local.data(), h + (first + c) * _m);
  }
  MatDenseRestoreArray(_H, &h);
  MatDenseRestoreArrayRead(AE, &ae);
  for (Mat* M : {&E, &R, &X, &AE})
    MatDestroy(M);
}

void SchurComplement::condensed_load(Vec b, Vec g)
{
  // v = A_C^{-1} b with b_C zeroed solves the equations of I with x_C = 0;
  // then g = b_C - (A v)_C.
  VecCopy(b, _w);
  PetscScalar* w = nullptr;
  VecGetArray(_w, &w);
  for (std::int32_t d : _dofs)
    w[d] = 0;
  VecRestoreArray(_w, &w);
  _solver->solve(_v, _w);
  MatMult(_A, _v, _w);
  const PetscScalar *B, *Av;
  VecGetArrayRead(b, &B);
  VecGetArrayRead(_w, &Av);
  std::vector<PetscScalar> local(_dofs.size());
  for (std::size_t k = 0; k < _dofs.size(); ++k)
    local[k] = B[_dofs[k]] - Av[_dofs[k]];
  VecRestoreArrayRead(b, &B);
  VecRestoreArrayRead(_w, &Av);
  PetscScalar* G = nullptr;
  VecGetArray(g, &G);
  gather(local.data(), G);
  VecRestoreArray(g, &G);
}

void SchurComplement::restrict_to_contact(Vec x, Vec y)
{
  const PetscScalar* X;
  VecGetArrayRead(x, &X);
  std::vector<PetscScalar> local(_dofs.size());
  for (std::size_t k = 0; k < _dofs.size(); ++k)
    local[k] = X[_dofs[k]];
  VecRestoreArrayRead(x, &X);
  PetscScalar* Y = nullptr;
  VecGetArray(y, &Y);
  gather(local.data(), Y);
  VecRestoreArray(y, &Y);
}

void SchurComplement::extend(Vec b, Vec y, Vec x)
{
  // A_C x = r with r = b - A y (y embedded by zeros) and r_C = y: the rows
  // of C give x_C = y, those of I give A_II x_I = b_I - A_IC y.
  const PetscScalar* Y;
  VecGetArrayRead(y, &Y);
  PetscScalar* v = nullptr;
  VecSet(_v, 0);
  VecGetArray(_v, &v);
  for (std::size_t k = 0; k < _dofs.size(); ++k)
    v[_dofs[k]] = Y[_offset + k];
  VecRestoreArray(_v, &v);
  MatMult(_A, _v, _w);
  VecAYPX(_w, -1.0, b);
  PetscScalar* w = nullptr;
  VecGetArray(_w, &w);
  for (std::size_t k = 0; k < _dofs.size(); ++k)
    w[_dofs[k]] = Y[_offset + k];
  VecRestoreArray(_w, &w);
  VecRestoreArrayRead(y, &Y);
  _solver->solve(x, _w);
}

} // namespace biotcontact
