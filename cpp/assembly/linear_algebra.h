// Assembly helpers shared by the steps (how systems are solved: solver.h).
#pragma once

#include <dolfinx/fem/DirichletBC.h>
#include <dolfinx/fem/Form.h>
#include <dolfinx/fem/FunctionSpace.h>
#include <dolfinx/la/Vector.h>
#include <dolfinx/la/petsc.h>
#include <memory>
#include <petscmat.h>
#include <petscvec.h>
#include <span>
#include <string>
#include <vector>

namespace biotcontact
{

using BCs = std::vector<std::shared_ptr<const dolfinx::fem::DirichletBC<double>>>;

/// @brief One field within a vector of unknowns: its own (collapsed) space
/// and the position in the vector of each of its entries (empty: the
/// vector is the field's own). A checkpoint stores the unknowns field by field.
struct UnknownsPart
{
  std::string name;
  std::shared_ptr<const dolfinx::fem::FunctionSpace> space;
  std::span<const std::int32_t> position;
};

/// Euclidean norm of the owned part of a DOF array of V (collective).
double owned_norm(std::span<const double> x, const dolfinx::fem::FunctionSpace& V);

/// The largest |x[i]| over the positions `dofs` on every rank (collective).
double largest_entry(std::span<const double> x, std::span<const std::int32_t> dofs, MPI_Comm comm);

/// @brief Every rank's values, in rank order, on every rank: `values`, and
/// `offsets` (size + 1) where each rank's part starts.
struct Gathered
{
  std::vector<std::int64_t> values;
  std::vector<int> offsets;
};

/// Gathers every rank's `values` on every rank (collective).
Gathered all_gather(const std::vector<std::int64_t>& values, MPI_Comm comm);

/// The global position in a solved vector (its rows from `start` on this
/// rank) of each global DOF of V in `dofs`, wherever it is owned:
/// `displacement_dofs[i]` is the place of V's owned DOF i, `dof_offset` the
/// global index of this rank's first. A fault's other face may be owned by
/// another rank, so every request goes to every rank (collective).
std::vector<PetscInt> solved_positions(const std::vector<std::int64_t>& dofs, PetscInt start,
                                       std::span<const std::int32_t> displacement_dofs, std::int64_t dof_offset,
                                       MPI_Comm comm);

/// A copy of the values (ghosts included) of a function or vector.
std::vector<double> values(std::span<const double> x);

/// Sets the values of f (ghosts included) from `x`, of f's length.
void assign(dolfinx::fem::Function<double>& f, std::span<const double> x);

/// Assembles a bilinear form; rows and columns of Dirichlet DOFs become
/// identity rows (the right-hand side gets the lifting, see assemble_rhs).
dolfinx::la::petsc::Matrix assemble_matrix(const dolfinx::fem::Form<double>& a, const BCs& bcs);

/// Assembles a into the existing matrix A (same sparsity), as above; the
/// solvers that use A refactorise it at their next solve.
void reassemble_matrix(Mat A, const dolfinx::fem::Form<double>& a, const BCs& bcs);

/// Assembles a bilinear form that acts on an iterate (a rectangular
/// operator, applied with MatMult every coupling iteration instead of
/// assembling its action): rows of the Dirichlet DOFs of its test space are
/// zero, so the product leaves the Dirichlet values of a right-hand side alone.
dolfinx::la::petsc::Matrix assemble_operator(const dolfinx::fem::Form<double>& a, const BCs& bcs);

/// Assembles a into the existing operator A (same sparsity), as above.
void reassemble_operator(Mat A, const dolfinx::fem::Form<double>& a, const BCs& bcs);

/// d = a - b, entry by entry (owned and ghost entries).
void difference(const dolfinx::la::Vector<double>& a, const dolfinx::la::Vector<double>& b,
                dolfinx::la::Vector<double>& d);

/// a - b, entry by entry, as a new array.
std::vector<double> difference(std::span<const double> a, std::span<const double> b);

/// y += A x on the owned parts of dolfinx vectors (collective).
void multiply_add(Mat A, const dolfinx::la::Vector<double>& x, dolfinx::la::Vector<double>& y);

/// Adds the local contributions of L to b (no ghost accumulation).
void add_vector(dolfinx::la::Vector<double>& b, const dolfinx::fem::Form<double>& L);

/// Finishes a right-hand side: accumulates ghosts, lifts the Dirichlet values
/// of `a` and sets them in the Dirichlet rows.
void finish_rhs(dolfinx::la::Vector<double>& b, std::shared_ptr<const dolfinx::fem::Form<double>> a,
                const BCs& bcs);

/// The rigid-body modes of a P1 vector space V (d translations and
/// d(d-1)/2 rotations about the origin, orthonormalised): the near-nullspace
/// of elasticity, from which smoothed aggregation builds its coarse spaces.
/// With `position`, laid out for another numbering of V's owned DOFs:
/// owned DOF i of V is entry position[i] there (the displacement block of
/// the coupled system); a node's components must stay together, in order.
MatNullSpace rigid_body_modes(const dolfinx::fem::FunctionSpace& V, const std::vector<std::int32_t>& position = {});

/// Number of owned (unrolled) DOFs of V on this rank.
std::int32_t owned_size(const dolfinx::fem::FunctionSpace& V);

/// PETSc's global indices of the local DOFs `local` of a space with block
/// size 1 and index map `map` that this rank owns, ascending.
std::vector<PetscInt> owned_global_dofs(const dolfinx::common::IndexMap& map,
                                        const std::vector<std::int32_t>& local);

/// The matrix R that places V's DOFs in a mixed space X of which V is a
/// collapsed part: R(i, V_to_X[i]) = 1 for V's owned DOFs i (global rows
/// of V, columns of X; X has block size 1 and owns V's owned DOFs). An
/// operator M on V acts on X as M R.
Mat placement(const dolfinx::fem::FunctionSpace& V, const std::vector<std::int32_t>& V_to_X,
              const dolfinx::fem::FunctionSpace& X);

/// Wraps a dolfinx vector (owned part) as a PETSc Vec sharing its memory.
dolfinx::la::petsc::Vector wrap(dolfinx::la::Vector<double>& x);

} // namespace biotcontact
