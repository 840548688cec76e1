// The contact constraints of a displacement space, whatever pairs them (a
// face against a rigid foundation: foundation_pair.h; the two faces of a
// fault: fault_pair.h): per constraint the DOF that carries it after the
// change of variables, its gap, normal and lumped measure, and the blocks
// of that change, and the contact law of each contact boundary.
#pragma once

#include "assembly/forms.h"
#include "contact/change_of_variables.h"
#include "contact/contact_law.h"
#include "domain/domain.h"

#include <dolfinx/fem/Function.h>
#include <dolfinx/la/Vector.h>
#include <memory>
#include <mpi.h>
#include <petscvec.h>
#include <span>
#include <string>
#include <vector>

namespace biotcontact
{

/// @brief A block of the change of variables in V's numbering: the global
/// (unrolled) DOFs of V it mixes, and its matrix (change_of_variables.h).
struct ContactBlock
{
  std::vector<std::int64_t> dofs;
  std::vector<double> T;
};

/// The contact constraints of a P1 displacement space V: one for each node
/// of a contact boundary (owned by this rank) and each foundation it
/// touches (two at the apex of a groove), u.nu_F <= g_a.
struct ContactSet
{
  /// Per constraint: the DOF in V (unrolled) that carries u.nu_F after the
  /// change of variables, as sign * x'[dof] (sign +-1 at a node whose
  /// normals are coordinate axes, where the DOF is that component of u
  /// itself; +1 at a transformed node); its gap, its normal and its lumped
  /// boundary measure (which turns a nodal force into a pressure).
  std::vector<std::int32_t> dofs;
  std::vector<int> sign;
  std::vector<double> gap, lumped;
  std::vector<std::array<double, 3>> normal;
  /// Per constraint of a fault pair: the input index of its + node and R,
  /// the rotation of the pair's jump (pair_change_of_variables); for a
  /// foundation's constraint -1, and T_node where the node has a change of
  /// variables (a frictional one always does: its rows 1..d-1 are the
  /// tangents friction acts along).
  std::vector<std::int64_t> pair_node;
  std::vector<NodeMatrix> pair_frame;
  /// Per constraint of a fault pair where faults cross or end on one
  /// another (fault_pair.h, junctions): the global nodes of V of its + and
  /// - nodes; (-1, -1) elsewhere. Its row of x' is its normal jump alone
  /// (junction_change_of_variables), so its slip is measured on u
  /// (junction_jumps), and it is frictionless. `all_junction_nodes`: the
  /// global nodes of every junction, on every rank.
  std::vector<std::array<std::int64_t, 2>> junction_nodes;
  std::vector<std::int64_t> all_junction_nodes;
  /// Per constraint: whether friction acts on it (its law holds something
  /// and no displacement component of its node is prescribed); then rows
  /// 1..d-1 of its change of variables, at dofs[k] + 1.., are its tangents.
  std::vector<char> frictional;
  /// Per constraint: the rock's shear modulus G at a fault pair's + node (0
  /// for a foundation's), whose product with the slip is the seismic
  /// moment (pair_shear_moduli).
  std::vector<double> shear_modulus;
  /// Per constraint, its contact boundary (of `boundaries`, a fault's name
  /// for its pairs; a constraint merged from two boundaries counts for the
  /// first). `faults` flags the boundaries that are faults, `laws` holds
  /// the contact law of each (contact_law.h; frictionless until the scene
  /// gives friction).
  std::vector<int> boundary;
  std::vector<std::string> boundaries;
  std::vector<char> faults;
  std::vector<ContactLaw> laws;
  /// Per constraint: whether its cohesion still holds (contact_law.h, "the
  /// bond"); empty or 1 until its pair opens (ContactSolver keeps it).
  std::vector<char> bonded;
  /// The blocks of the change of variables (change_of_variables.h): the
  /// nodes whose normals are not coordinate axes (T_node) and the node
  /// pairs of faults, by the global (unrolled) DOFs of V they mix.
  std::vector<ContactBlock> blocks;
  /// The global index in V (unrolled) of this rank's first owned DOF.
  std::int64_t dof_offset = 0;
  int dim = 2;
  /// A P1 scalar space, for output, and each constraint's node there.
  std::shared_ptr<const dolfinx::fem::FunctionSpace> output_space;
  std::vector<std::int32_t> output_dofs;
};

/// The law of constraint k: its boundary's, without the cohesion once
/// its bond broke (contact_law.h).
ContactLaw constraint_law(const ContactSet& set, std::size_t k);

/// Whether any rank has a frictional constraint (collective).
bool any_frictional(const ContactSet& set, MPI_Comm comm);

/// The displacement scale of x (the solved vector, V's owned DOF i at
/// displacement_dofs[i]): the largest gap or |displacement|, 1 when both
/// are 0; the contact VI works in its units (collective).
double displacement_scale(const ContactSet& set, std::span<const std::int32_t> displacement_dofs, Vec x,
                          MPI_Comm comm);

/// Flags of the DOFs of V (unrolled, local, ghosts too) whose value a
/// displacement condition prescribes.
std::vector<char> prescribed_dofs(const Scene& scene, const Domain& domain, const dolfinx::fem::FunctionSpace& V);

/// The lumped boundary measure of each DOF of V on `facets`: the integral
/// of its hat function over them.
dolfinx::la::Vector<double> lumped_measure(const Domain& domain, const CompiledForms& forms,
                                           std::shared_ptr<const dolfinx::fem::FunctionSpace> V,
                                           std::vector<std::int32_t> facets);

/// The shear modulus of each constraint of `set`: at a fault pair, the
/// mean of the DG0 coefficient G over the cells of its + node (all of them
/// on the + side of the split; a node on a layer interface has cells of
/// both layers); 0 at a foundation's constraint (collective).
std::vector<double> pair_shear_moduli(const ContactSet& set, const dolfinx::fem::FunctionSpace& V,
                                      const dolfinx::fem::Function<double>& G);

/// The contact boundary as a P1 field for output: exactly 1 at the contact
/// nodes, 0 elsewhere.
std::shared_ptr<dolfinx::fem::Function<double>> contact_boundary_flag(const ContactSet& set);

/// The output fields of a contact set: the contact pressure and active flag
/// (zero off Gamma_3) and the contact_boundary_flag.
void make_contact_fields(const ContactSet& set, std::shared_ptr<dolfinx::fem::Function<double>>& pressure,
                         std::shared_ptr<dolfinx::fem::Function<double>>& active,
                         std::shared_ptr<dolfinx::fem::Function<double>>& boundary);

} // namespace biotcontact
