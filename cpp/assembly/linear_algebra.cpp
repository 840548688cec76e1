#include "assembly/linear_algebra.h"

#include "assembly/node_coordinates.h"
#include "assembly/petsc_error.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <dolfinx/fem/assembler.h>
#include <dolfinx/fem/petsc.h>

namespace biotcontact
{
using namespace dolfinx;

double owned_norm(std::span<const double> x, const fem::FunctionSpace& V)
{
  const std::size_t owned = owned_size(V);
  double local = 0;
  for (std::size_t i = 0; i < owned; ++i)
    local += x[i] * x[i];
  double global = 0;
  MPI_Allreduce(&local, &global, 1, MPI_DOUBLE, MPI_SUM, V.mesh()->comm());
  return std::sqrt(global);
}

double largest_entry(std::span<const double> x, std::span<const std::int32_t> dofs, MPI_Comm comm)
{
  double largest = 0;
  for (std::int32_t i : dofs)
    largest = std::max(largest, std::abs(x[i]));
  MPI_Allreduce(MPI_IN_PLACE, &largest, 1, MPI_DOUBLE, MPI_MAX, comm);
  return largest;
}

std::vector<PetscInt> solved_positions(const std::vector<std::int64_t>& dofs, PetscInt start,
                                       std::span<const std::int32_t> displacement_dofs, std::int64_t dof_offset,
                                       MPI_Comm comm)
{
  const auto owned = static_cast<std::int64_t>(displacement_dofs.size());
  const Gathered requests = all_gather(dofs, comm);
  const std::vector<std::int64_t>& all = requests.values;
  std::vector<std::int64_t> answer(all.size(), -1);
  for (std::size_t k = 0; k < all.size(); ++k)
    if (const std::int64_t i = all[k] - dof_offset; i >= 0 and i < owned)
      answer[k] = start + displacement_dofs[i];
  MPI_Allreduce(MPI_IN_PLACE, answer.data(), static_cast<int>(answer.size()), MPI_INT64_T, MPI_MAX, comm);
  int rank = 0;
  MPI_Comm_rank(comm, &rank);
  return std::vector<PetscInt>(answer.begin() + requests.offsets[rank], answer.begin() + requests.offsets[rank + 1]);
}

std::vector<double> values(std::span<const double> x) { return std::vector<double>(x.begin(), x.end()); }

void assign(fem::Function<double>& f, std::span<const double> x)
{
  std::copy(x.begin(), x.end(), f.x()->mutable_array().begin());
}

la::petsc::Matrix assemble_matrix(const fem::Form<double>& a, const BCs& bcs)
{
  la::petsc::Matrix A(fem::petsc::create_matrix(a), false);
  reassemble_matrix(A.mat(), a, bcs);
  return A;
}

void reassemble_matrix(Mat A, const fem::Form<double>& a, const BCs& bcs)
{
  // The operator, then 1 on the diagonal of the Dirichlet rows.
  reassemble_operator(A, a, bcs);
  fem::set_diagonal<double>(la::petsc::Matrix::set_fn(A, INSERT_VALUES), *a.function_spaces()[0], bcs);
  check_petsc(MatAssemblyBegin(A, MAT_FINAL_ASSEMBLY), "assembling a matrix: MatAssemblyBegin");
  check_petsc(MatAssemblyEnd(A, MAT_FINAL_ASSEMBLY), "assembling a matrix: MatAssemblyEnd");
}

la::petsc::Matrix assemble_operator(const fem::Form<double>& a, const BCs& bcs)
{
  la::petsc::Matrix A(fem::petsc::create_matrix(a), false);
  reassemble_operator(A.mat(), a, bcs);
  return A;
}

void reassemble_operator(Mat A, const fem::Form<double>& a, const BCs& bcs)
{
  check_petsc(MatZeroEntries(A), "assembling an operator: MatZeroEntries");
  fem::assemble_matrix(la::petsc::Matrix::set_block_fn(A, ADD_VALUES), a, bcs);
  check_petsc(MatAssemblyBegin(A, MAT_FINAL_ASSEMBLY), "assembling an operator: MatAssemblyBegin");
  check_petsc(MatAssemblyEnd(A, MAT_FINAL_ASSEMBLY), "assembling an operator: MatAssemblyEnd");
}

void difference(const la::Vector<double>& a, const la::Vector<double>& b, la::Vector<double>& d)
{
  std::transform(a.array().begin(), a.array().end(), b.array().begin(), d.mutable_array().begin(),
                 std::minus<double>());
}

std::vector<double> difference(std::span<const double> a, std::span<const double> b)
{
  std::vector<double> d(a.size());
  std::transform(a.begin(), a.end(), b.begin(), d.begin(), std::minus<double>());
  return d;
}

void multiply_add(Mat A, const la::Vector<double>& x, la::Vector<double>& y)
{
  // MatMult only reads x: the wrap of a const vector is safe.
  la::petsc::Vector xv = wrap(const_cast<la::Vector<double>&>(x)), yv = wrap(y);
  check_petsc(MatMultAdd(A, xv.vec(), yv.vec(), yv.vec()), "y += A x: MatMultAdd");
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

namespace
{
/// PETSc duplicates a communicator for its objects and frees the duplicate
/// with the last object on it: a Vec made and destroyed each coupling
/// iteration would duplicate `comm` each time (a collective set-up, a third
/// of a small run's time). One reference is kept for the life of `comm`,
/// marked by an attribute of our own so that it is taken once.
void keep_petsc_comm(MPI_Comm comm)
{
  static int kept = MPI_KEYVAL_INVALID;
  if (kept == MPI_KEYVAL_INVALID)
    MPI_Comm_create_keyval(MPI_COMM_NULL_COPY_FN, MPI_COMM_NULL_DELETE_FN, &kept, nullptr);
  int found = 0;
  void* value = nullptr;
  MPI_Comm_get_attr(comm, kept, &value, &found);
  if (found)
    return;
  MPI_Comm inner;
  check_petsc(PetscCommDuplicate(comm, &inner, nullptr), "wrapping a vector: PetscCommDuplicate");
  MPI_Comm_set_attr(comm, kept, nullptr);
}
} // namespace

la::petsc::Vector wrap(la::Vector<double>& x)
{
  // Owned entries only: no ghost scatter to build (the products, norms and
  // solves on a wrap never read ghosts).
  const common::IndexMap& map = *x.map();
  const int bs = x.bs();
  keep_petsc_comm(map.comm());
  Vec v;
  check_petsc(VecCreateMPIWithArray(map.comm(), bs, bs * map.size_local(), bs * map.size_global(),
                                    x.mutable_array().data(), &v),
              "wrapping a vector: VecCreateMPIWithArray");
  return la::petsc::Vector(v, false);
}

MatNullSpace rigid_body_modes(const fem::FunctionSpace& V, const std::vector<std::int32_t>& position)
{
  // PETSc builds the modes from the coordinates of the owned nodes, given
  // as a vector with the block size d laid out like the displacement.
  const int d = V.dofmap()->index_map_bs();
  const std::int32_t nodes = V.dofmap()->index_map->size_local();
  const std::vector<double> x = node_coordinates(V); // 3 per node
  Vec coordinates;
  check_petsc(VecCreateMPI(V.mesh()->comm(), d * nodes, PETSC_DETERMINE, &coordinates),
              "the rigid-body modes: VecCreateMPI");
  check_petsc(VecSetBlockSize(coordinates, d), "the rigid-body modes: VecSetBlockSize");
  PetscScalar* c;
  check_petsc(VecGetArray(coordinates, &c), "the rigid-body modes: VecGetArray");
  for (std::int32_t i = 0; i < nodes; ++i)
    for (int k = 0; k < d; ++k)
    {
      const std::int32_t at = position.empty() ? d * i + k : position[d * i + k];
      if (at % d != k)
        throw std::logic_error("rigid_body_modes: the numbering splits the components of a node");
      c[at] = x[3 * i + k];
    }
  check_petsc(VecRestoreArray(coordinates, &c), "the rigid-body modes: VecRestoreArray");
  MatNullSpace modes;
  check_petsc(MatNullSpaceCreateRigidBody(coordinates, &modes), "the rigid-body modes: MatNullSpaceCreateRigidBody");
  check_petsc(VecDestroy(&coordinates), "the rigid-body modes: VecDestroy");
  return modes;
}

std::int32_t owned_size(const fem::FunctionSpace& V)
{
  return V.dofmap()->index_map->size_local() * V.dofmap()->index_map_bs();
}

Mat placement(const fem::FunctionSpace& V, const std::vector<std::int32_t>& V_to_X, const fem::FunctionSpace& X)
{
  const std::int32_t rows = owned_size(V), columns = owned_size(X);
  const std::int64_t first_row = V.dofmap()->index_map->local_range()[0] * V.dofmap()->index_map_bs();
  const std::int64_t first_column = X.dofmap()->index_map->local_range()[0];
  Mat R = nullptr;
  const MPI_Comm comm = V.mesh()->comm();
  check_petsc(MatCreateAIJ(comm, rows, columns, PETSC_DETERMINE, PETSC_DETERMINE, 1, nullptr, 1, nullptr, &R),
              "the placement matrix: MatCreateAIJ");
  for (std::int32_t i = 0; i < rows; ++i)
    check_petsc(MatSetValue(R, static_cast<PetscInt>(first_row + i), static_cast<PetscInt>(first_column + V_to_X[i]),
                            1.0, INSERT_VALUES),
                "the placement matrix: MatSetValue");
  check_petsc(MatAssemblyBegin(R, MAT_FINAL_ASSEMBLY), "the placement matrix: MatAssemblyBegin");
  check_petsc(MatAssemblyEnd(R, MAT_FINAL_ASSEMBLY), "the placement matrix: MatAssemblyEnd");
  return R;
}

std::vector<PetscInt> owned_global_dofs(const common::IndexMap& map, const std::vector<std::int32_t>& local)
{
  const std::int32_t owned = map.size_local();
  const std::int64_t first = map.local_range()[0];
  std::vector<PetscInt> dofs;
  for (std::int32_t i : local)
    if (i < owned)
      dofs.push_back(static_cast<PetscInt>(first + i));
  std::sort(dofs.begin(), dofs.end());
  return dofs;
}

Gathered all_gather(const std::vector<std::int64_t>& values, MPI_Comm comm)
{
  int size = 0;
  MPI_Comm_size(comm, &size);
  const int count = static_cast<int>(values.size());
  std::vector<int> counts(size);
  Gathered g{{}, std::vector<int>(size + 1, 0)};
  MPI_Allgather(&count, 1, MPI_INT, counts.data(), 1, MPI_INT, comm);
  for (int r = 0; r < size; ++r)
    g.offsets[r + 1] = g.offsets[r] + counts[r];
  g.values.resize(g.offsets[size]);
  MPI_Allgatherv(values.data(), count, MPI_INT64_T, g.values.data(), counts.data(), g.offsets.data(), MPI_INT64_T,
                 comm);
  return g;
}

} // namespace biotcontact
