#include "linear_algebra.h"

#include <dolfinx/fem/assembler.h>
#include <dolfinx/fem/petsc.h>

namespace biotcontact
{
using namespace dolfinx;

la::petsc::Matrix assemble_matrix(const fem::Form<double>& a, const BCs& bcs)
{
  la::petsc::Matrix A(fem::petsc::create_matrix(a), false);
  reassemble_matrix(A.mat(), a, bcs);
  return A;
}

void reassemble_matrix(Mat A, const fem::Form<double>& a, const BCs& bcs)
{
  MatZeroEntries(A);
  fem::assemble_matrix(la::petsc::Matrix::set_block_fn(A, ADD_VALUES), a, bcs);
  MatAssemblyBegin(A, MAT_FLUSH_ASSEMBLY);
  MatAssemblyEnd(A, MAT_FLUSH_ASSEMBLY);
  fem::set_diagonal<double>(la::petsc::Matrix::set_fn(A, INSERT_VALUES), *a.function_spaces()[0], bcs);
  MatAssemblyBegin(A, MAT_FINAL_ASSEMBLY);
  MatAssemblyEnd(A, MAT_FINAL_ASSEMBLY);
}

void add_vector(la::Vector<double>& b, const fem::Form<double>& L)
{
  fem::assemble_vector(b.mutable_array(), L);
}

void finish_rhs(la::Vector<double>& b, std::shared_ptr<const fem::Form<double>> a, const BCs& bcs)
{
  if (!bcs.empty())
    fem::apply_lifting<double>(b.mutable_array(), {a}, {bcs}, {}, 1.0);
  b.scatter_rev(std::plus<double>());
  if (!bcs.empty())
    fem::set_bc(b.mutable_array(), bcs);
}

void set_default_option(const std::string& name, const std::string& value)
{
  PetscBool given = PETSC_FALSE;
  PetscOptionsHasName(nullptr, nullptr, ("-" + name).c_str(), &given);
  if (!given)
    PetscOptionsSetValue(nullptr, ("-" + name).c_str(), value.c_str());
}

void set_solver_defaults(const std::string& prefix)
{
  // A preconditioner other than a factorisation is no solver by itself:
  // then the default Krylov method is GMRES instead of a single application.
  char pc[64] = "";
  PetscBool set = PETSC_FALSE;
  PetscOptionsGetString(nullptr, prefix.c_str(), "-pc_type", pc, sizeof pc, &set);
  const bool direct = !set or std::string(pc) == "lu" or std::string(pc) == "cholesky";
  set_default_option(prefix + "ksp_type", direct ? "preonly" : "gmres");
  set_default_option(prefix + "pc_type", "lu");
  if (direct)
  {
    set_default_option(prefix + "pc_factor_mat_solver_type", "mumps");
    set_default_option(prefix + "mat_mumps_icntl_14", "400");
  }
}

LinearSolver::LinearSolver(MPI_Comm comm, const std::string& prefix, Mat A) : _prefix(prefix)
{
  set_solver_defaults(prefix);
  KSPCreate(comm, &_ksp);
  KSPSetOptionsPrefix(_ksp, prefix.c_str());
  KSPSetOperators(_ksp, A, A);
  if (PetscErrorCode ierr = KSPSetFromOptions(_ksp); ierr != 0)
    throw OptionsError("the PETSc options of the " + prefix.substr(0, prefix.size() - 1)
                       + " solver do not make a solver (PETSc error " + std::to_string(ierr) + ")");
}

LinearSolver::~LinearSolver() { KSPDestroy(&_ksp); }

int LinearSolver::solve(Vec x, Vec b)
{
  if (PetscErrorCode ierr = KSPSolve(_ksp, b, x); ierr != 0)
    throw SolverError("the " + _prefix.substr(0, _prefix.size() - 1) + " linear solver failed: PETSc error "
                      + std::to_string(ierr));
  KSPConvergedReason reason;
  KSPGetConvergedReason(_ksp, &reason);
  if (reason < 0)
    throw SolverError("the " + _prefix.substr(0, _prefix.size() - 1)
                      + " linear solver failed: " + KSPConvergedReasons[reason]);
  PetscInt its = 0;
  KSPGetIterationNumber(_ksp, &its);
  return static_cast<int>(its);
}

la::petsc::Vector wrap(la::Vector<double>& x)
{
  return la::petsc::Vector(la::petsc::create_vector_wrap(x), false);
}

} // namespace biotcontact
