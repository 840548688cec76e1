#include "contact/change_of_variables.h"

#include "solvers/solver.h"

#include <algorithm>
#include <cmath>
#include <mpi.h>

namespace biotcontact
{

namespace
{
/// check_petsc for the change of variables' calls; `what` names the call.
void check(PetscErrorCode code, const char* what) { check_petsc(code, "the change of variables", what); }

double dot(const double* a, const double* b, int d)
{
  double s = 0;
  for (int i = 0; i < d; ++i)
    s += a[i] * b[i];
  return s;
}

double determinant(const NodeMatrix& T, int d)
{
  if (d == 2)
    return T[0] * T[3] - T[1] * T[2];
  return T[0] * (T[4] * T[8] - T[5] * T[7]) - T[1] * (T[3] * T[8] - T[5] * T[6]) + T[2] * (T[3] * T[7] - T[4] * T[6]);
}

/// v less its parts along the first `rows` (orthonormal) rows of Q,
/// normalised, into row `rows` of Q; false when nothing (to 1e-8) is left.
bool orthonormal_to(std::array<double, 3> v, NodeMatrix& Q, int rows, int d)
{
  for (int r = 0; r < rows; ++r)
  {
    const double c = dot(v.data(), &Q[3 * r], d);
    for (int i = 0; i < d; ++i)
      v[i] -= c * Q[3 * r + i];
  }
  const double length = std::sqrt(dot(v.data(), v.data(), d));
  if (length < 1e-8)
    return false;
  for (int i = 0; i < d; ++i)
    Q[3 * rows + i] = v[i] / length;
  return true;
}

/// Orthonormal rows completing the first m rows of T (which span the
/// normals) to a basis: Gram-Schmidt of the coordinate axes against the
/// rows so far, each axis kept when it adds a direction. Works on Q, an
/// orthonormal basis of the span of every row so far.
void complete(NodeMatrix& T, NodeMatrix Q, int m, int d)
{
  int rows = m;
  for (int axis = 0; axis < d and rows < d; ++axis)
  {
    std::array<double, 3> e{0, 0, 0};
    e[axis] = 1;
    if (!orthonormal_to(e, Q, rows, d))
      continue;
    std::copy_n(&Q[3 * rows], d, &T[3 * rows]);
    ++rows;
  }
}
} // namespace

std::optional<std::pair<int, int>> coordinate_axis(const std::array<double, 3>& normal, int d)
{
  int axis = -1;
  for (int i = 0; i < d; ++i)
  {
    if (std::abs(normal[i]) > 1 - 1e-14)
      axis = i;
    else if (std::abs(normal[i]) > 1e-14)
      return std::nullopt;
  }
  if (axis < 0)
    return std::nullopt;
  return std::make_pair(axis, normal[axis] > 0 ? 1 : -1);
}

std::optional<NodeMatrix> node_change_of_variables(const std::vector<std::array<double, 3>>& normals, int d,
                                                   const std::array<bool, 3>& prescribed)
{
  const int m = static_cast<int>(normals.size());
  // Rows stored with stride 3 whatever d: T[3 r + i]; packed to d x d below.
  NodeMatrix T{}, Q{};
  for (int r = 0; r < m; ++r)
  {
    std::copy_n(normals[r].begin(), d, &T[3 * r]);
    // Q: the normals orthonormalised; a normal (nearly) in the span of the
    // ones before it is not an independent constraint.
    if (!orthonormal_to(normals[r], Q, r, d))
      return std::nullopt;
  }
  complete(T, Q, m, d);
  NodeMatrix square{};
  for (int r = 0; r < d; ++r)
    for (int i = 0; i < d; ++i)
      square[d * r + i] = T[3 * r + i];
  if (std::abs(determinant(square, d)) < 1e-8)
    return std::nullopt;
  // A prescribed component must stay one of the new variables: then no
  // normal has a part along it (and completion keeps its axis), unless
  // every component is prescribed (the node does not move at all).
  const bool all = std::all_of(prescribed.begin(), prescribed.begin() + d, [](bool p) { return p; });
  for (int i = 0; i < d and !all; ++i)
    for (int r = 0; r < m and prescribed[i]; ++r)
      if (std::abs(normals[r][i]) > 1e-12)
        return std::nullopt;
  return square;
}

std::vector<double> inverse(const std::vector<double>& T, int n)
{
  // [T | I] reduced to [I | T^-1].
  std::vector<double> a(T), inv(n * n, 0.0);
  for (int i = 0; i < n; ++i)
    inv[n * i + i] = 1;
  for (int c = 0; c < n; ++c)
  {
    int pivot = c;
    for (int r = c + 1; r < n; ++r)
      if (std::abs(a[n * r + c]) > std::abs(a[n * pivot + c]))
        pivot = r;
    for (int j = 0; j < n; ++j)
    {
      std::swap(a[n * c + j], a[n * pivot + j]);
      std::swap(inv[n * c + j], inv[n * pivot + j]);
    }
    const double p = a[n * c + c];
    for (int j = 0; j < n; ++j)
    {
      a[n * c + j] /= p;
      inv[n * c + j] /= p;
    }
    for (int r = 0; r < n; ++r)
    {
      const double f = a[n * r + c];
      if (r == c or f == 0)
        continue;
      for (int j = 0; j < n; ++j)
      {
        a[n * r + j] -= f * a[n * c + j];
        inv[n * r + j] -= f * inv[n * c + j];
      }
    }
  }
  return inv;
}

std::vector<double> node_block(const NodeMatrix& T, int d) { return std::vector<double>(T.begin(), T.begin() + d * d); }

std::vector<double> pair_change_of_variables(const NodeMatrix& R, int d)
{
  const int n = 2 * d;
  std::vector<double> B(n * n, 0.0);
  for (int r = 0; r < d; ++r)
  {
    for (int c = 0; c < d; ++c)
    {
      B[n * r + c] = R[d * r + c];
      B[n * r + d + c] = -R[d * r + c];
    }
    B[n * (d + r) + r] = 0.5;
    B[n * (d + r) + d + r] = 0.5;
  }
  return B;
}

namespace
{
/// v less its parts along the rows of Q (orthonormal, n wide), normalised
/// and appended to Q; false when nothing (to 1e-8 of |v|) is left.
bool append_orthonormal(std::vector<double> v, std::vector<double>& Q, int n)
{
  const double norm = std::sqrt(dot(v.data(), v.data(), n));
  for (std::size_t r = 0; r < Q.size() / n; ++r)
  {
    const double c = dot(v.data(), &Q[n * r], n);
    for (int i = 0; i < n; ++i)
      v[i] -= c * Q[n * r + i];
  }
  const double length = std::sqrt(dot(v.data(), v.data(), n));
  if (length < 1e-8 * norm)
    return false;
  for (int i = 0; i < n; ++i)
    Q.push_back(v[i] / length);
  return true;
}
} // namespace

std::optional<std::vector<double>> junction_change_of_variables(const std::vector<JunctionPair>& pairs, int m,
                                                                int d, const std::vector<char>& prescribed)
{
  const int n = m * d;
  std::vector<double> B(n * n, 0.0), Q; // Q: an orthonormal basis of the rows so far
  std::vector<char> taken(prescribed.begin(), prescribed.end());
  for (int j = 0; j < n; ++j)
    if (prescribed[j])
    {
      std::vector<double> e(n, 0.0);
      e[j] = B[n * j + j] = 1;
      append_orthonormal(e, Q, n);
    }
  for (const JunctionPair& p : pairs)
  {
    const int row = d * p.plus + p.row;
    std::vector<double> v(n, 0.0);
    for (int i = 0; i < d; ++i)
      v[d * p.plus + i] = p.normal[i], v[d * p.minus + i] = -p.normal[i];
    for (int j = 0; j < n; ++j)
      if (prescribed[j] and std::abs(v[j]) > 1e-12)
        return std::nullopt;
    if (taken[row] or !append_orthonormal(v, Q, n))
      return std::nullopt;
    std::copy(v.begin(), v.end(), &B[n * row]);
    taken[row] = 1;
  }
  // Each free row: the first unit vector (its own, then the others) that
  // adds a direction, less its parts along the rows so far.
  for (int row = 0; row < n; ++row)
    for (int k = 0; !taken[row] and k < n; ++k)
    {
      std::vector<double> e(n, 0.0);
      e[(row + k) % n] = 1;
      if (append_orthonormal(e, Q, n))
      {
        std::copy(Q.end() - n, Q.end(), &B[n * row]);
        taken[row] = 1;
      }
    }
  return B;
}

namespace
{
/// The identity with the blocks (T's or their inverses) in place: every
/// rank adds 1 on its diagonal, each block's rank adds B - I on its rows,
/// which another rank may own (collective).
Mat block_diagonal(Mat A, const std::vector<ChangeOfVariables::Block>& blocks, bool inverted)
{
  PetscInt m = 0, n = 0, M = 0, N = 0, start = 0, bs = 1;
  check(MatGetLocalSize(A, &m, &n), "MatGetLocalSize of A");
  check(MatGetSize(A, &M, &N), "MatGetSize of A");
  check(MatGetOwnershipRange(A, &start, nullptr), "MatGetOwnershipRange of A");
  check(MatGetBlockSize(A, &bs), "MatGetBlockSize of A");
  const MPI_Comm comm = PetscObjectComm(reinterpret_cast<PetscObject>(A));
  PetscInt width = 1;
  for (const auto& block : blocks)
    width = std::max(width, static_cast<PetscInt>(block.dofs.size()));
  MPI_Allreduce(MPI_IN_PLACE, &width, 1, MPIU_INT, MPI_MAX, comm);
  Mat T;
  check(MatCreateAIJ(comm, m, n, M, N, width, nullptr, width, nullptr, &T), "MatCreateAIJ of T");
  check(MatSetBlockSize(T, bs), "MatSetBlockSize of T");
  for (PetscInt i = 0; i < m; ++i)
    check(MatSetValue(T, start + i, start + i, 1.0, ADD_VALUES), "MatSetValue of T");
  for (const auto& block : blocks)
  {
    const int k = static_cast<int>(block.dofs.size());
    std::vector<double> B = inverted ? inverse(block.T, k) : block.T;
    for (int i = 0; i < k; ++i)
      B[k * i + i] -= 1;
    check(MatSetValues(T, k, block.dofs.data(), k, block.dofs.data(), B.data(), ADD_VALUES), "MatSetValues of T");
  }
  check(MatAssemblyBegin(T, MAT_FINAL_ASSEMBLY), "MatAssemblyBegin of T");
  check(MatAssemblyEnd(T, MAT_FINAL_ASSEMBLY), "MatAssemblyEnd of T");
  return T;
}
} // namespace

ChangeOfVariables::ChangeOfVariables(Mat A, const std::vector<Block>& blocks, bool spd)
    : _T(block_diagonal(A, blocks, false)), _T_inverse(block_diagonal(A, blocks, true)), _spd(spd)
{
}

ChangeOfVariables::~ChangeOfVariables()
{
  warn_petsc(MatDestroy(&_T), "the change of variables: MatDestroy of T");
  warn_petsc(MatDestroy(&_T_inverse), "the change of variables: MatDestroy of T^-1");
}

void ChangeOfVariables::forward(Vec x, Vec y) const { check(MatMult(_T, x, y), "MatMult of T"); }

void ChangeOfVariables::backward(Vec y, Vec x) const { check(MatMult(_T_inverse, y, x), "MatMult of T^-1"); }

void ChangeOfVariables::dual(Vec f, Vec g) const
{
  check(MatMultTranspose(_T_inverse, f, g), "MatMultTranspose of T^-1");
}

void ChangeOfVariables::congruence(Mat A, Mat* At) const
{
  check(MatPtAP(A, _T_inverse, *At ? MAT_REUSE_MATRIX : MAT_INITIAL_MATRIX, PETSC_DEFAULT, At), "MatPtAP of A");
  if (_spd)
    check(MatSetOption(*At, MAT_SPD, PETSC_TRUE), "MatSetOption MAT_SPD of A'");
  MatNullSpace modes = nullptr;
  check(MatGetNearNullSpace(A, &modes), "MatGetNearNullSpace of A");
  if (modes)
  {
    MatNullSpace t = transformed(modes);
    check(MatSetNearNullSpace(*At, t), "MatSetNearNullSpace of A'");
    check(MatNullSpaceDestroy(&t), "MatNullSpaceDestroy");
  }
}

/// T v for a vector v of a field: v placed into a vector like `layout`,
/// changed, and read back.
void ChangeOfVariables::forward_field(Vec v, Vec t, const std::vector<PetscInt>& dofs, Vec layout) const
{
  Vec whole, changed;
  check(VecDuplicate(layout, &whole), "VecDuplicate of the layout");
  check(VecDuplicate(layout, &changed), "VecDuplicate of the layout");
  PetscInt start = 0;
  check(VecGetOwnershipRange(layout, &start, nullptr), "VecGetOwnershipRange of the layout");
  const PetscScalar* in;
  PetscScalar *w, *out;
  check(VecGetArrayRead(v, &in), "VecGetArrayRead of a field's vector");
  check(VecGetArray(whole, &w), "VecGetArray of a whole vector");
  for (std::size_t i = 0; i < dofs.size(); ++i)
    w[dofs[i] - start] = in[i];
  check(VecRestoreArray(whole, &w), "VecRestoreArray of a whole vector");
  check(VecRestoreArrayRead(v, &in), "VecRestoreArrayRead of a field's vector");
  forward(whole, changed);
  check(VecGetArrayRead(changed, &in), "VecGetArrayRead of a changed vector");
  check(VecGetArray(t, &out), "VecGetArray of a field's vector");
  for (std::size_t i = 0; i < dofs.size(); ++i)
    out[i] = in[dofs[i] - start];
  check(VecRestoreArray(t, &out), "VecRestoreArray of a field's vector");
  check(VecRestoreArrayRead(changed, &in), "VecRestoreArrayRead of a changed vector");
  check(VecDestroy(&whole), "VecDestroy of a whole vector");
  check(VecDestroy(&changed), "VecDestroy of a changed vector");
}

MatNullSpace ChangeOfVariables::transformed(MatNullSpace modes, const std::vector<PetscInt>* dofs, Vec layout) const
{
  PetscBool has_constant = PETSC_FALSE;
  PetscInt n = 0;
  const Vec* vectors = nullptr;
  check(MatNullSpaceGetVecs(modes, &has_constant, &n, &vectors), "MatNullSpaceGetVecs of the near-nullspace");
  // T v, orthonormalised again (PETSc asks it of a null space; a node on
  // two foundations has a T that is not orthogonal).
  std::vector<Vec> t(n);
  for (PetscInt k = 0; k < n; ++k)
  {
    check(VecDuplicate(vectors[k], &t[k]), "VecDuplicate of a near-nullspace vector");
    if (dofs)
      forward_field(vectors[k], t[k], *dofs, layout);
    else
      forward(vectors[k], t[k]);
    for (PetscInt j = 0; j < k; ++j)
    {
      PetscScalar c = 0;
      check(VecDot(t[k], t[j], &c), "VecDot of near-nullspace vectors");
      check(VecAXPY(t[k], -c, t[j]), "VecAXPY of near-nullspace vectors");
    }
    check(VecNormalize(t[k], nullptr), "VecNormalize of a near-nullspace vector");
  }
  MatNullSpace space;
  check(MatNullSpaceCreate(PetscObjectComm(reinterpret_cast<PetscObject>(modes)), has_constant, n, t.data(), &space),
        "MatNullSpaceCreate of the transformed near-nullspace");
  for (Vec& v : t)
    check(VecDestroy(&v), "VecDestroy of a near-nullspace vector");
  return space;
}

} // namespace biotcontact
