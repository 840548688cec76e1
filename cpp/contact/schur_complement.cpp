#include "contact/schur_complement.h"

#include <algorithm>
#include <dolfinx/common/Timer.h>

namespace biotcontact
{

namespace
{
/// check_petsc for the Schur complement's calls; `what` names the call.
void check(PetscErrorCode code, const char* what) { check_petsc(code, "the Schur complement", what); }
} // namespace

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
  check(MatGetOwnershipRange(A, &_first_row, nullptr), "MatGetOwnershipRange of A");
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
  check(MatCreateVecs(A, &_v, &_w), "MatCreateVecs of A");
  if (_whole and _ranks > 1)
  {
    check(VecScatterCreateToAll(_w, &_to_all, &_b_whole), "VecScatterCreateToAll");
    check(VecDuplicate(_b_whole, &_x_whole), "VecDuplicate of the whole right-hand side");
  }
  check(MatCreateSeqDense(PETSC_COMM_SELF, _m, _m, nullptr, &_H), "MatCreateSeqDense of H");
}

SchurComplement::~SchurComplement()
{
  _solver.reset();
  warn_petsc(MatDestroy(&_clamped), "the Schur complement: MatDestroy of A_C");
  warn_petsc(MatDestroy(&_A_whole), "the Schur complement: MatDestroy of A gathered");
  warn_petsc(MatDestroy(&_H), "the Schur complement: MatDestroy of H");
  warn_petsc(VecScatterDestroy(&_to_all), "the Schur complement: VecScatterDestroy");
  for (Vec* v : {&_v, &_w, &_b_whole, &_x_whole})
    warn_petsc(VecDestroy(v), "the Schur complement: VecDestroy");
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
  check(MatDestroy(&_A_whole), "MatDestroy of A gathered");
  check(MatCreateRedundantMatrix(_A, _ranks, PETSC_COMM_SELF, MAT_INITIAL_MATRIX, &_A_whole),
        "MatCreateRedundantMatrix of A");
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
  check(VecScatterBegin(_to_all, b, _b_whole, INSERT_VALUES, SCATTER_FORWARD), "VecScatterBegin to every rank");
  check(VecScatterEnd(_to_all, b, _b_whole, INSERT_VALUES, SCATTER_FORWARD), "VecScatterEnd to every rank");
  _solver->solve(_x_whole, _b_whole);
  PetscInt lo = 0, hi = 0;
  check(VecGetOwnershipRange(x, &lo, &hi), "VecGetOwnershipRange of x");
  const PetscScalar* all;
  PetscScalar* own;
  check(VecGetArrayRead(_x_whole, &all), "VecGetArrayRead of the whole solution");
  check(VecGetArray(x, &own), "VecGetArray of x");
  std::copy(all + lo, all + hi, own);
  check(VecRestoreArray(x, &own), "VecRestoreArray of x");
  check(VecRestoreArrayRead(_x_whole, &all), "VecRestoreArrayRead of the whole solution");
}

void SchurComplement::assemble()
{
  // A_C: the contact DOFs clamped (identity rows and columns). Its
  // factorisation is the system's one (the same options, the same log
  // stage), on each rank's whole copy when the system's is (PCREDUNDANT).
  _solver.reset();
  check(MatDestroy(&_clamped), "MatDestroy of A_C");
  gather_whole();
  check(MatDuplicate(solve_matrix(), MAT_COPY_VALUES, &_clamped), "MatDuplicate of A");
  check(MatZeroRowsColumns(_clamped, static_cast<PetscInt>(_rows.size()), _rows.data(), 1.0, nullptr, nullptr),
        "MatZeroRowsColumns of A_C");
  const std::string prefix = _A_whole ? _prefix + "redundant_" : _prefix;
  _solver = std::make_unique<LinearSolver>(PetscObjectComm(reinterpret_cast<PetscObject>(_clamped)), prefix,
                                           _clamped, _clamped, _structure);
  _solver->set_up();

  dolfinx::common::Timer timer("Schur complement");

  int partial = _whole and _m >= partial_factorisation_from and factorise_with_schur(solve_matrix()) == 0;
  // Decided on every rank alike: where one rank's partial factorisation
  // failed (its memory), every rank forms its share of the columns, which
  // share_columns exchanges.
  MPI_Allreduce(MPI_IN_PLACE, &partial, 1, MPI_INT, MPI_LAND, _comm);
  if (partial)
  {
    ++factorizations;
    time += timer.stop();
    return;
  }
  // Blocks of right-hand sides: one call into the factorisation each, with
  // the dense blocks (n x block) kept to a few tens of megabytes. Each
  // rank with a whole copy forms its share of the columns.
  PetscInt n = 0;
  check(MatGetSize(_A, &n, nullptr), "MatGetSize of A");
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
  check(MatDenseGetArray(_H, &h), "MatDenseGetArray of H");
  MPI_Allgatherv(MPI_IN_PLACE, 0, MPI_DATATYPE_NULL, h, counts.data(), displacements.data(), MPIU_SCALAR, _comm);
  check(MatDenseRestoreArray(_H, &h), "MatDenseRestoreArray of H");
}

void SchurComplement::form_columns(PetscInt first, PetscInt count)
{
  // Column j of H is (A E_j)_C with E_j = e_j - A_C^{-1} (A e_j)|_I: the
  // unit displacement of contact DOF j, extended to I by the equations of
  // I with the other contact DOFs held at zero.
  Mat S = solve_matrix();
  PetscInt n_local = 0;
  check(MatGetLocalSize(S, &n_local, nullptr), "MatGetLocalSize of A");
  Mat E, R, X, AE;
  check(MatCreateDense(PetscObjectComm(reinterpret_cast<PetscObject>(S)), n_local, PETSC_DECIDE, PETSC_DETERMINE,
                       count, nullptr, &E),
        "MatCreateDense of the unit columns");
  for (std::size_t i = 0; i < _rows.size(); ++i)
    if (const PetscInt j = column_of(i); j >= first and j < first + count)
      check(MatSetValue(E, _rows[i], j - first, 1.0, INSERT_VALUES), "MatSetValue of the unit columns");
  check(MatAssemblyBegin(E, MAT_FINAL_ASSEMBLY), "MatAssemblyBegin of the unit columns");
  check(MatAssemblyEnd(E, MAT_FINAL_ASSEMBLY), "MatAssemblyEnd of the unit columns");

  // R = (A e_j) with the rows of C zeroed; X = A_C^{-1} R vanishes on C.
  check(MatMatMult(S, E, MAT_INITIAL_MATRIX, PETSC_DEFAULT, &R), "MatMatMult of A and the unit columns");
  {
    PetscScalar* r = nullptr;
    PetscInt lda = 0;
    check(MatDenseGetLDA(R, &lda), "MatDenseGetLDA of the right-hand sides");
    check(MatDenseGetArray(R, &r), "MatDenseGetArray of the right-hand sides");
    for (PetscInt c = 0; c < count; ++c)
      for (std::size_t i = 0; i < _rows.size(); ++i)
        r[local_index(i) + c * lda] = 0;
    check(MatDenseRestoreArray(R, &r), "MatDenseRestoreArray of the right-hand sides");
  }
  check(MatDuplicate(R, MAT_DO_NOT_COPY_VALUES, &X), "MatDuplicate of the right-hand sides");
  _solver->solve(X, R);
  check(MatAXPY(E, -1.0, X, SAME_NONZERO_PATTERN), "MatAXPY of the extended columns");
  check(MatMatMult(S, E, MAT_INITIAL_MATRIX, PETSC_DEFAULT, &AE), "MatMatMult of A and the extended columns");

  const PetscScalar* ae = nullptr;
  PetscInt lda = 0;
  check(MatDenseGetLDA(AE, &lda), "MatDenseGetLDA of A E");
  check(MatDenseGetArrayRead(AE, &ae), "MatDenseGetArrayRead of A E");
  PetscScalar* h = nullptr;
  check(MatDenseGetArray(_H, &h), "MatDenseGetArray of H"); // column-major, leading dimension m
  std::vector<PetscScalar> at_contact(_rows.size());
  for (PetscInt c = 0; c < count; ++c)
  {
    for (std::size_t i = 0; i < _rows.size(); ++i)
      at_contact[i] = ae[local_index(i) + c * lda];
    contact_values(at_contact.data(), h + (first + c) * _m);
  }
  check(MatDenseRestoreArray(_H, &h), "MatDenseRestoreArray of H");
  check(MatDenseRestoreArrayRead(AE, &ae), "MatDenseRestoreArrayRead of A E");
  for (Mat* M : {&E, &R, &X, &AE})
    check(MatDestroy(M), "MatDestroy of a block of columns");
}

void SchurComplement::condensed_load(Vec b, Vec g)
{
  // v = A_C^{-1} b with b_C zeroed solves the equations of I with x_C = 0;
  // then g = b_C - (A v)_C.
  check(VecCopy(b, _w), "VecCopy of the load");
  PetscScalar* w = nullptr;
  check(VecGetArray(_w, &w), "VecGetArray of the load");
  for (std::int32_t d : _dofs)
    w[d] = 0;
  check(VecRestoreArray(_w, &w), "VecRestoreArray of the load");
  solve(_v, _w);
  check(MatMult(_A, _v, _w), "MatMult of A");
  const PetscScalar *B, *Av;
  check(VecGetArrayRead(b, &B), "VecGetArrayRead of the load");
  check(VecGetArrayRead(_w, &Av), "VecGetArrayRead of A v");
  std::vector<PetscScalar> local(_dofs.size());
  for (std::size_t k = 0; k < _dofs.size(); ++k)
    local[k] = B[_dofs[k]] - Av[_dofs[k]];
  check(VecRestoreArrayRead(b, &B), "VecRestoreArrayRead of the load");
  check(VecRestoreArrayRead(_w, &Av), "VecRestoreArrayRead of A v");
  PetscScalar* G = nullptr;
  check(VecGetArray(g, &G), "VecGetArray of the condensed load");
  gather(local.data(), G);
  check(VecRestoreArray(g, &G), "VecRestoreArray of the condensed load");
}

void SchurComplement::restrict_to_contact(Vec x, Vec y)
{
  const PetscScalar* X;
  check(VecGetArrayRead(x, &X), "VecGetArrayRead of x");
  std::vector<PetscScalar> local(_dofs.size());
  for (std::size_t k = 0; k < _dofs.size(); ++k)
    local[k] = X[_dofs[k]];
  check(VecRestoreArrayRead(x, &X), "VecRestoreArrayRead of x");
  PetscScalar* Y = nullptr;
  check(VecGetArray(y, &Y), "VecGetArray of x_C");
  gather(local.data(), Y);
  check(VecRestoreArray(y, &Y), "VecRestoreArray of x_C");
}

void SchurComplement::extend(Vec b, Vec y, Vec x)
{
  // A_C x = r with r = b - A y (y embedded by zeros) and r_C = y: the rows
  // of C give x_C = y, those of I give A_II x_I = b_I - A_IC y.
  const PetscScalar* Y;
  check(VecGetArrayRead(y, &Y), "VecGetArrayRead of y");
  PetscScalar* v = nullptr;
  check(VecSet(_v, 0), "VecSet of y embedded");
  check(VecGetArray(_v, &v), "VecGetArray of y embedded");
  for (std::size_t k = 0; k < _dofs.size(); ++k)
    v[_dofs[k]] = Y[_offset + k];
  check(VecRestoreArray(_v, &v), "VecRestoreArray of y embedded");
  check(MatMult(_A, _v, _w), "MatMult of A");
  check(VecAYPX(_w, -1.0, b), "VecAYPX of the load");
  PetscScalar* w = nullptr;
  check(VecGetArray(_w, &w), "VecGetArray of the right-hand side");
  for (std::size_t k = 0; k < _dofs.size(); ++k)
    w[_dofs[k]] = Y[_offset + k];
  check(VecRestoreArray(_w, &w), "VecRestoreArray of the right-hand side");
  check(VecRestoreArrayRead(y, &Y), "VecRestoreArrayRead of y");
  solve(x, _w);
}

} // namespace biotcontact
