#include "contact/schur_complement.h"

#include <algorithm>
#include <dolfinx/common/Timer.h>

namespace biotcontact
{

SchurComplement::SchurComplement(MPI_Comm comm, const std::string& prefix, Mat A, Structure structure,
                                 std::vector<std::int32_t> dofs)
    : _comm(comm), _prefix(prefix), _A(A), _structure(structure), _dofs(std::move(dofs))
{
  MPI_Comm_size(comm, &_ranks);
  MPI_Comm_rank(comm, &_rank);
  const int local = static_cast<int>(_dofs.size());
  _counts.resize(_ranks);
  MPI_Allgather(&local, 1, MPI_INT, _counts.data(), 1, MPI_INT, comm);
  _displacements.resize(_ranks);
  for (int r = 0, sum = 0; r < _ranks; sum += _counts[r], ++r)
    _displacements[r] = sum;
  _offset = _displacements[_rank];
  _m = _displacements.back() + _counts.back();
  MatGetOwnershipRange(A, &_first_row, nullptr);
  _whole = _ranks == 1 or option(prefix, "-pc_type") == "redundant";
  std::vector<PetscInt> own(_dofs.size());
  std::transform(_dofs.begin(), _dofs.end(), own.begin(), [&](std::int32_t d) { return _first_row + d; });
  if (_whole)
  {
    // Every contact row, in H's order, on every rank.
    _rows.resize(_m);
    MPI_Allgatherv(own.data(), local, MPIU_INT, _rows.data(), _counts.data(), _displacements.data(), MPIU_INT, comm);
  }
  else
    _rows = own;
  MatCreateVecs(A, &_v, &_w);
  if (_whole and _ranks > 1)
  {
    VecScatterCreateToAll(_w, &_to_all, &_b_whole);
    VecDuplicate(_b_whole, &_x_whole);
  }
  MatCreateSeqDense(PETSC_COMM_SELF, _m, _m, nullptr, &_H);
}

SchurComplement::~SchurComplement()
{
  _solver.reset();
  MatDestroy(&_clamped);
  MatDestroy(&_A_whole);
  MatDestroy(&_H);
  VecScatterDestroy(&_to_all);
  for (Vec* v : {&_v, &_w, &_b_whole, &_x_whole})
    VecDestroy(v);
}

void SchurComplement::gather(const PetscScalar* local, PetscScalar* all) const
{
  MPI_Allgatherv(local, static_cast<int>(_dofs.size()), MPI_DOUBLE, all,
                 _counts.data(), _displacements.data(), MPI_DOUBLE, _comm);
}

void SchurComplement::contact_values(const PetscScalar* at_contact, PetscScalar* all) const
{
  if (_whole)
    std::copy(at_contact, at_contact + _m, all);
  else
    gather(at_contact, all);
}

PetscInt SchurComplement::local_index(std::size_t i) const
{
  return _rows[i] - (_A_whole ? 0 : _first_row);
}

PetscInt SchurComplement::column_of(std::size_t i) const
{
  return _whole ? static_cast<PetscInt>(i) : _offset + static_cast<PetscInt>(i);
}

void SchurComplement::gather_whole()
{
  if (!_whole or _ranks == 1)
    return;
  MatDestroy(&_A_whole);
  MatCreateRedundantMatrix(_A, _ranks, PETSC_COMM_SELF, MAT_INITIAL_MATRIX, &_A_whole);
}

void SchurComplement::solve(Vec x, Vec b)
{
  if (!_A_whole)
  {
    _solver->solve(x, b);
    return;
  }
  // The whole right-hand side to every rank, the whole solution on each;
  // each rank keeps its own part (as PCREDUNDANT does).
  VecScatterBegin(_to_all, b, _b_whole, INSERT_VALUES, SCATTER_FORWARD);
  VecScatterEnd(_to_all, b, _b_whole, INSERT_VALUES, SCATTER_FORWARD);
  _solver->solve(_x_whole, _b_whole);
  PetscInt lo = 0, hi = 0;
  VecGetOwnershipRange(x, &lo, &hi);
  const PetscScalar* all;
  PetscScalar* own;
  VecGetArrayRead(_x_whole, &all);
  VecGetArray(x, &own);
  std::copy(all + lo, all + hi, own);
  VecRestoreArray(x, &own);
  VecRestoreArrayRead(_x_whole, &all);
}

void SchurComplement::assemble()
{
  // A_C: the contact DOFs clamped (identity rows and columns). Its
  // factorisation is the system's one (the same options, the same log
  // stage), on each rank's whole copy when the system's is (PCREDUNDANT).
  _solver.reset();
  MatDestroy(&_clamped);
  gather_whole();
  MatDuplicate(solve_matrix(), MAT_COPY_VALUES, &_clamped);
  MatZeroRowsColumns(_clamped, static_cast<PetscInt>(_rows.size()), _rows.data(), 1.0, nullptr, nullptr);
  const std::string prefix = _A_whole ? _prefix + "redundant_" : _prefix;
  _solver = std::make_unique<LinearSolver>(PetscObjectComm(reinterpret_cast<PetscObject>(_clamped)), prefix,
                                           _clamped, _clamped, _structure);
  _solver->set_up();

  dolfinx::common::Timer timer("Schur complement");

  if (_whole and _m >= partial_factorisation_from and factorise_with_schur(solve_matrix()) == 0)
  {
    ++factorizations;
    time += timer.stop();
    return;
  }
  // Blocks of right-hand sides: one call into the factorisation each, with
  // the dense blocks (n x block) kept to a few tens of megabytes. Each
  // rank with a whole copy forms its share of the columns.
  PetscInt n = 0;
  MatGetSize(_A, &n, nullptr);
  const PetscInt block = std::clamp<PetscInt>(static_cast<PetscInt>(4e6 / std::max<PetscInt>(n, 1)), 1, 64);
  const PetscInt begin = _whole ? _m * _rank / _ranks : 0, end = _whole ? _m * (_rank + 1) / _ranks : _m;
  for (PetscInt first = begin; first < end; first += block)
    form_columns(first, std::min(block, end - first));
  if (_A_whole)
    share_columns();
  columns += _m;
  time += timer.stop();
}

PetscErrorCode SchurComplement::factorise_with_schur(Mat S)
{
  PetscFunctionBeginUser;
#if defined(PETSC_HAVE_MUMPS)
  // Only for an SPD A (the mechanics): MUMPS's analysis refuses the
  // Schur variables of the monolithic system (INFOG(1) = -4).
  if (_structure != Structure::spd)
    PetscFunctionReturn(PETSC_ERR_SUP);
  // MUMPS wants the Schur variables in ascending order: H's row i is the
  // sorted position order[i] of _rows[i].
  std::vector<PetscInt> sorted(_rows.begin(), _rows.end()), order(_m);
  std::sort(sorted.begin(), sorted.end());
  for (PetscInt i = 0; i < _m; ++i)
    order[i] = std::lower_bound(sorted.begin(), sorted.end(), _rows[i]) - sorted.begin();
  Mat F = nullptr, Sc = nullptr;
  IS schur = nullptr, rows = nullptr, cols = nullptr;
  MatFactorInfo info;
  MatFactorSchurStatus status;
  PetscCall(MatFactorInfoInitialize(&info));
  PetscCall(MatGetFactor(S, MATSOLVERMUMPS, MAT_FACTOR_CHOLESKY, &F));
  PetscCall(ISCreateGeneral(PETSC_COMM_SELF, _m, sorted.data(), PETSC_COPY_VALUES, &schur));
  PetscCall(MatFactorSetSchurIS(F, schur));
  PetscCall(MatGetOrdering(S, MATORDERINGNATURAL, &rows, &cols));
  PetscCall(MatCholeskyFactorSymbolic(F, S, rows, &info));
  for (IS* is : {&schur, &rows, &cols}) // the factor keeps its own copies
    PetscCall(ISDestroy(is));
  PetscCall(MatCholeskyFactorNumeric(F, S, &info));
  // MUMPS reports a failed analysis or factorisation here, not as an error
  // code: then the columns are solved as without MUMPS.
  MatFactorError failed = MAT_FACTOR_NOERROR;
  PetscCall(MatFactorGetError(F, &failed));
  if (failed != MAT_FACTOR_NOERROR)
  {
    PetscCall(MatDestroy(&F));
    PetscFunctionReturn(PETSC_ERR_LIB);
  }
  PetscCall(MatFactorCreateSchurComplement(F, &Sc, &status));
  const PetscScalar* sc = nullptr;
  PetscScalar* h = nullptr;
  PetscInt ls = 0;
  PetscCall(MatDenseGetLDA(Sc, &ls));
  PetscCall(MatDenseGetArrayRead(Sc, &sc));
  PetscCall(MatDenseGetArray(_H, &h)); // column-major, leading dimension m
  for (PetscInt j = 0; j < _m; ++j)
    for (PetscInt i = 0; i < _m; ++i)
      h[i + j * _m] = sc[order[i] + order[j] * ls];
  PetscCall(MatDenseRestoreArray(_H, &h));
  PetscCall(MatDenseRestoreArrayRead(Sc, &sc));
  PetscCall(MatDestroy(&Sc));
  PetscCall(MatDestroy(&F));
  PetscFunctionReturn(0);
#else
  PetscFunctionReturn(PETSC_ERR_SUP);
#endif
}

void SchurComplement::share_columns()
{
  // H is column-major with leading dimension m: rank r's columns
  // [m r / R, m (r + 1) / R) are one contiguous block.
  std::vector<int> counts(_ranks), displacements(_ranks);
  for (int r = 0; r < _ranks; ++r)
  {
    displacements[r] = static_cast<int>(_m * (_m * r / _ranks));
    counts[r] = static_cast<int>(_m * (_m * (r + 1) / _ranks)) - displacements[r];
  }
  PetscScalar* h = nullptr;
  MatDenseGetArray(_H, &h);
  MPI_Allgatherv(MPI_IN_PLACE, 0, MPI_DATATYPE_NULL, h, counts.data(), displacements.data(), MPIU_SCALAR, _comm);
  MatDenseRestoreArray(_H, &h);
}

void SchurComplement::form_columns(PetscInt first, PetscInt count)
{
  // Column j of H is (A E_j)_C with E_j = e_j - A_C^{-1} (A e_j)|_I: the
  // unit displacement of contact DOF j, extended to I by the equations of
  // I with the other contact DOFs held at zero.
  Mat S = solve_matrix();
  PetscInt n_local = 0;
  MatGetLocalSize(S, &n_local, nullptr);
  Mat E, R, X, AE;
  MatCreateDense(PetscObjectComm(reinterpret_cast<PetscObject>(S)), n_local, PETSC_DECIDE, PETSC_DETERMINE, count,
                 nullptr, &E);
  for (std::size_t i = 0; i < _rows.size(); ++i)
    if (const PetscInt j = column_of(i); j >= first and j < first + count)
      MatSetValue(E, _rows[i], j - first, 1.0, INSERT_VALUES);
  MatAssemblyBegin(E, MAT_FINAL_ASSEMBLY);
  MatAssemblyEnd(E, MAT_FINAL_ASSEMBLY);

  // R = (A e_j) with the rows of C zeroed; X = A_C^{-1} R vanishes on C.
  MatMatMult(S, E, MAT_INITIAL_MATRIX, PETSC_DEFAULT, &R);
  {
    PetscScalar* r = nullptr;
    PetscInt lda = 0;
    MatDenseGetLDA(R, &lda);
    MatDenseGetArray(R, &r);
    for (PetscInt c = 0; c < count; ++c)
      for (std::size_t i = 0; i < _rows.size(); ++i)
        r[local_index(i) + c * lda] = 0;
    MatDenseRestoreArray(R, &r);
  }
  MatDuplicate(R, MAT_DO_NOT_COPY_VALUES, &X);
  _solver->solve(X, R);
  MatAXPY(E, -1.0, X, SAME_NONZERO_PATTERN);
  MatMatMult(S, E, MAT_INITIAL_MATRIX, PETSC_DEFAULT, &AE);

  const PetscScalar* ae = nullptr;
  PetscInt lda = 0;
  MatDenseGetLDA(AE, &lda);
  MatDenseGetArrayRead(AE, &ae);
  PetscScalar* h = nullptr;
  MatDenseGetArray(_H, &h); // column-major, leading dimension m
  std::vector<PetscScalar> at_contact(_rows.size());
  for (PetscInt c = 0; c < count; ++c)
  {
    for (std::size_t i = 0; i < _rows.size(); ++i)
      at_contact[i] = ae[local_index(i) + c * lda];
    contact_values(at_contact.data(), h + (first + c) * _m);
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
  solve(_v, _w);
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
  solve(x, _w);
}

} // namespace biotcontact
