// Assembly helpers shared by the steps (how systems are solved: solver.h).
#pragma once

#include <dolfinx/fem/DirichletBC.h>
#include <dolfinx/fem/Form.h>
#include <dolfinx/la/Vector.h>
#include <dolfinx/la/petsc.h>
#include <memory>
#include <petscvec.h>
#include <vector>

namespace biotcontact
{

using BCs = std::vector<std::shared_ptr<const dolfinx::fem::DirichletBC<double>>>;

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

/// Wraps a dolfinx vector (owned part) as a PETSc Vec sharing its memory.
dolfinx::la::petsc::Vector wrap(dolfinx::la::Vector<double>& x);

} // namespace biotcontact
