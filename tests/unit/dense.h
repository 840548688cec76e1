// Small dense matrices for the contact algebra's unit tests: a symmetric
// positive definite one, products, solves, and their PETSc copies (AIJ
// matrices and vectors on one rank) to hand to the code under test.
#pragma once

#include <algorithm>
#include <cmath>
#include <petscmat.h>
#include <stdexcept>
#include <utility>
#include <vector>

namespace unit
{

/// A row-major n x n matrix.
struct Dense
{
  int n = 0;
  std::vector<double> a;
  explicit Dense(int size) : n(size), a(size * size, 0.0) {}
  double& operator()(int i, int j) { return a[n * i + j]; }
  double operator()(int i, int j) const { return a[n * i + j]; }
};

/// A_ij = 1 / (1 + |i - j|) + n delta_ij: full, symmetric, and positive
/// definite (strictly diagonally dominant: the off-diagonal sum of a row is
/// below 2 (1/2 + ... + 1/n) < n).
inline Dense spd_matrix(int n)
{
  Dense A(n);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j)
      A(i, j) = 1.0 / (1 + std::abs(i - j)) + (i == j ? n : 0);
  return A;
}

inline Dense product(const Dense& A, const Dense& B)
{
  Dense C(A.n);
  for (int i = 0; i < A.n; ++i)
    for (int k = 0; k < A.n; ++k)
      for (int j = 0; j < A.n; ++j)
        C(i, j) += A(i, k) * B(k, j);
  return C;
}

inline Dense transpose(const Dense& A)
{
  Dense T(A.n);
  for (int i = 0; i < A.n; ++i)
    for (int j = 0; j < A.n; ++j)
      T(i, j) = A(j, i);
  return T;
}

inline std::vector<double> product(const Dense& A, const std::vector<double>& x)
{
  std::vector<double> y(A.n, 0.0);
  for (int i = 0; i < A.n; ++i)
    for (int j = 0; j < A.n; ++j)
      y[i] += A(i, j) * x[j];
  return y;
}

/// X with A X = B (B's columns: `columns` vectors of A.n entries each), by
/// Gaussian elimination with partial pivoting.
inline std::vector<std::vector<double>> solve(Dense A, std::vector<std::vector<double>> B)
{
  const int n = A.n;
  for (int k = 0; k < n; ++k)
  {
    int p = k;
    for (int i = k + 1; i < n; ++i)
      if (std::abs(A(i, k)) > std::abs(A(p, k)))
        p = i;
    if (A(p, k) == 0)
      throw std::runtime_error("singular matrix");
    for (int j = 0; j < n; ++j)
      std::swap(A(k, j), A(p, j));
    for (auto& b : B)
      std::swap(b[k], b[p]);
    for (int i = k + 1; i < n; ++i)
    {
      const double f = A(i, k) / A(k, k);
      for (int j = k; j < n; ++j)
        A(i, j) -= f * A(k, j);
      for (auto& b : B)
        b[i] -= f * b[k];
    }
  }
  for (auto& b : B)
    for (int i = n - 1; i >= 0; --i)
    {
      for (int j = i + 1; j < n; ++j)
        b[i] -= A(i, j) * b[j];
      b[i] /= A(i, i);
    }
  return B;
}

/// The largest absolute entry.
inline double largest(const std::vector<double>& v)
{
  double m = 0;
  for (double x : v)
    m = std::max(m, std::abs(x));
  return m;
}

/// A as a PETSc AIJ matrix on PETSC_COMM_WORLD (one rank).
inline Mat petsc_matrix(const Dense& A)
{
  Mat M;
  MatCreateAIJ(PETSC_COMM_WORLD, PETSC_DECIDE, PETSC_DECIDE, A.n, A.n, A.n, nullptr, 0, nullptr, &M);
  std::vector<PetscInt> all(A.n);
  for (int i = 0; i < A.n; ++i)
    all[i] = i;
  MatSetValues(M, A.n, all.data(), A.n, all.data(), A.a.data(), INSERT_VALUES);
  MatAssemblyBegin(M, MAT_FINAL_ASSEMBLY);
  MatAssemblyEnd(M, MAT_FINAL_ASSEMBLY);
  return M;
}

/// A PETSc matrix as a dense one.
inline Dense dense(Mat M)
{
  PetscInt n = 0;
  MatGetSize(M, &n, nullptr);
  Dense A(static_cast<int>(n));
  for (PetscInt i = 0; i < n; ++i)
    for (PetscInt j = 0; j < n; ++j)
      MatGetValue(M, i, j, &A(i, j));
  return A;
}

/// A vector like M's columns holding `values`.
inline Vec petsc_vector(Mat M, const std::vector<double>& values)
{
  Vec v;
  MatCreateVecs(M, &v, nullptr);
  PetscScalar* a = nullptr;
  VecGetArray(v, &a);
  std::copy(values.begin(), values.end(), a);
  VecRestoreArray(v, &a);
  return v;
}

inline std::vector<double> values(Vec v)
{
  PetscInt n = 0;
  VecGetLocalSize(v, &n);
  const PetscScalar* a = nullptr;
  VecGetArrayRead(v, &a);
  std::vector<double> out(a, a + n);
  VecRestoreArrayRead(v, &a);
  return out;
}

} // namespace unit
