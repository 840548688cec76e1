// Assembly and solver helpers shared by the flow and mechanics steps.
#pragma once

#include <dolfinx/fem/DirichletBC.h>
#include <dolfinx/fem/Form.h>
#include <dolfinx/la/Vector.h>
#include <dolfinx/la/petsc.h>
#include <memory>
#include <petscksp.h>
#include <stdexcept>
#include <string>
#include <vector>

namespace biotcontact
{

using BCs = std::vector<std::shared_ptr<const dolfinx::fem::DirichletBC<double>>>;

/// A solver that did not converge: the run stops with this message.
struct SolverError : std::runtime_error
{
  using std::runtime_error::runtime_error;
};

/// PETSc options that do not make a solver: bad input (exit 2).
struct OptionsError : std::runtime_error
{
  using std::runtime_error::runtime_error;
};

/// The direct-solver defaults of a solver with this options prefix: LU
/// (preonly) unless the command line says otherwise, MUMPS (with more
/// workspace than its default, for refactorisations) when the
/// factorisation is LU or Cholesky.
void set_solver_defaults(const std::string& prefix);

/// Assembles a bilinear form; rows and columns of Dirichlet DOFs become
/// identity rows (the right-hand side gets the lifting, see assemble_rhs).
dolfinx::la::petsc::Matrix assemble_matrix(const dolfinx::fem::Form<double>& a, const BCs& bcs);

/// Assembles a into the existing matrix A (same sparsity), as above; the
/// solvers that use A refactorise it at their next solve.
void reassemble_matrix(Mat A, const dolfinx::fem::Form<double>& a, const BCs& bcs);

/// Adds the local contributions of L to b (no ghost accumulation).
void add_vector(dolfinx::la::Vector<double>& b, const dolfinx::fem::Form<double>& L);

/// Finishes a right-hand side: accumulates ghosts, lifts the Dirichlet values
/// of `a` and sets them in the Dirichlet rows.
void finish_rhs(dolfinx::la::Vector<double>& b, std::shared_ptr<const dolfinx::fem::Form<double>> a,
                const BCs& bcs);

/// Sets a PETSc option unless the user already gave it (command line wins).
void set_default_option(const std::string& name, const std::string& value);

/// A KSP with an options prefix ("flow_", "mechanics_"); by default a direct
/// solve with MUMPS, which any -<prefix>ksp_type / -<prefix>pc_type overrides.
/// The operator is factorised once and reused for every solve.
class LinearSolver
{
public:
  LinearSolver(MPI_Comm comm, const std::string& prefix, Mat A);
  ~LinearSolver();
  LinearSolver(const LinearSolver&) = delete;
  LinearSolver& operator=(const LinearSolver&) = delete;

  /// Solves A x = b; returns the Krylov iterations. Throws SolverError.
  int solve(Vec x, Vec b);

private:
  KSP _ksp;
  std::string _prefix;
};

/// Wraps a dolfinx vector (owned part) as a PETSc Vec sharing its memory.
dolfinx::la::petsc::Vector wrap(dolfinx::la::Vector<double>& x);

} // namespace biotcontact
