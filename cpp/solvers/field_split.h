// The fields of a mixed system and how a PETSc field split preconditioner
// learns them: the index set of each field, what algebraic multigrid needs
// of a field's block (its block size and near-nullspace), and splits nested
// inside a split (the flow of the coupled system is itself split into flux
// and pressure, solver.h).
#pragma once

#include <memory>
#include <mpi.h>
#include <petscksp.h>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

namespace biotcontact
{

/// One field of a mixed system.
struct Field
{
  Field(std::string name, std::vector<PetscInt> dofs, PetscInt block_size = 1)
      : name(std::move(name)), dofs(std::move(dofs)), block_size(block_size)
  {
  }

  std::string name;
  /// Global indices of the owned DOFs, ascending: PETSc 3.18's parallel
  /// MatCreateSubMatrix loses entries of an unsorted index set.
  std::vector<PetscInt> dofs;
  /// DOFs per node when the field's DOFs come node by node (d for the
  /// displacement): AMG then aggregates nodes, not scalar DOFs.
  PetscInt block_size = 1;
  /// The near-nullspace of the field's block in its own numbering (the
  /// rigid-body modes of the displacement), or none.
  std::shared_ptr<std::remove_pointer_t<MatNullSpace>> near_nullspace;
  /// The splits of this field, numbered within the field's block (see
  /// part_of).
  std::vector<Field> fields;
};

/// Whether these are the fields of the coupled system: fields (flow,
/// mechanics) of which some are split further.
bool is_coupled(const std::vector<Field>& fields);

/// Takes ownership of a near-nullspace for Field::near_nullspace.
std::shared_ptr<std::remove_pointer_t<MatNullSpace>> own(MatNullSpace space);

/// The first row of this rank in the block of `whole`, which numbers its
/// rows rank by rank: the number of DOFs of `whole` on the ranks before it
/// (collective).
PetscInt block_offset(const Field& whole, MPI_Comm comm);

/// The field `name` made of `dofs` (global, owned, ascending), a subset of
/// `whole`'s DOFs, numbered within the block of `whole`: the block's rows
/// are `whole`'s DOFs in order, rank by rank (collective).
Field part_of(const Field& whole, const std::string& name, const std::vector<PetscInt>& dofs, MPI_Comm comm);

/// If `pc` is a field split without fields yet, gives it `fields` (before
/// it is set up), and, for a field with its own splits, sets its sub-
/// solver from the options and gives it those splits too. A field split
/// with no fields to split throws OptionsError, naming `prefix`.
void set_fields(PC pc, const std::vector<Field>& fields, const std::string& prefix);

} // namespace biotcontact
