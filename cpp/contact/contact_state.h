// The contact state after a solve and its report: the constraints' contact
// pressures and distances, each fault pair's jumps, tractions and state
// under its contact law (contact_law.h), and what the summary says of each
// contact boundary and fault.
#pragma once

#include "contact/contact_law.h"
#include "contact/contact_set.h"

#include <array>
#include <cstdint>
#include <dolfinx/fem/Function.h>
#include <map>
#include <mpi.h>
#include <petscsys.h>
#include <petscvec.h>
#include <span>
#include <string>
#include <tuple>
#include <vector>

namespace biotcontact
{

/// @brief A fault pair after a solve: its + node (input index), fault (index
/// among the contact's boundaries), opening [u].n + g0, contact traction
/// (normal, >= 0 pressing), slip (the tangential jump, a vector),
/// tangential traction (a vector: the one the + face exerts on the - face,
/// along the slip increment when the pair slips) and its state under the
/// fault's contact law (contact_law.h).
struct PairState
{
  std::int64_t node;
  int fault;
  double opening, traction;
  std::array<double, 3> slip, tangential_traction;
  PairStatus status;
  /// The slip since the start of the step (ContactSolver::set_slip_reference).
  std::array<double, 3> slip_increment;
  /// The cohesion its law holds: the fault's, 0 once its bond broke
  /// (contact_law.h).
  double cohesion = 0;
};

/// @brief What the summary says of a fault: its largest opening and slip,
/// the measures (lumped lengths in 2D, areas in 3D) of its pairs that are
/// closed, and of those in the states slip and stick, and the step's
/// seismic moment.
struct FaultSummary
{
  std::string name;
  double max_opening = 0, max_slip = 0, closed = 0, slipping = 0, stuck = 0;
  /// The seismic moment of the slip since the step's start: the sum over
  /// the pairs of G |slip increment| times their lumped measure (N m; N m
  /// per metre of thickness in 2D).
  double moment = 0;
};

/// The contact state after a solve: the contact force at a node is the
/// residual of the unconstrained equations there; divided by the lumped
/// measure it is the contact pressure -sigma_nu >= 0.
struct ContactState
{
  int active_nodes = 0;
  int contact_nodes = 0;
  double max_penetration = 0;     // max(u.nu_F - g_a), <= 0 when admissible
  double max_pressure = 0;        // max contact pressure
  double min_pressure = 0;        // min contact pressure (>= 0 up to tolerance)
  double max_complementarity = 0; // max |p_c (u.nu_F - g_a)|
  double gap_scale = 0;           // max(|g_a|, |u|)
  double total_force = 0;         // sum of the nodal contact forces along -nu_F
  /// Per contact boundary: its name, the sum of its nodal contact forces
  /// along -nu_F (the resultant's magnitude on a flat foundation) and its
  /// active constraints.
  std::vector<std::tuple<std::string, double, int>> boundaries;
  /// This rank's fault pairs (faults.h), each at its + node.
  std::vector<PairState> pairs;
  /// Per fault (in the order of the contact's boundaries): its largest
  /// opening and slip, and its measures in contact, slipping and stuck (a
  /// length in 2D, an area in 3D), on all ranks.
  std::vector<FaultSummary> faults;
};

/// @brief What the contact solver measured at a solution x, per constraint
/// of this rank (the set's order): its distance g - u.nu_F and contact
/// pressure; and the arrays of x' = T x, of x' at the step's start and of
/// the contact forces R' = T^{-T}(A x - b), where `displacement_dofs` places
/// V's owned DOFs (change_of_variables.h: a pair's + node's tangential rows
/// hold its tangential jump and force).
struct ContactMeasurement
{
  const ContactSet& set;
  std::span<const std::int32_t> displacement_dofs;
  std::span<const double> distance, pressure;
  double gap_scale;
  const PetscScalar *x, *start, *force;
  /// Per constraint at a junction, its jump [u] = u+ - u- at the solution
  /// and at the step's start (junction_jumps); empty without junctions.
  std::span<const std::array<double, 3>> jump, jump_start;
};

/// Per constraint of `set` at a junction of faults, the jump u+ - u- of its
/// pair in u, a vector whose owned DOFs of V sit at `displacement_dofs` (a
/// junction's pieces may be owned by several ranks; collective); zeros
/// elsewhere, nothing when no rank has a junction.
std::vector<std::array<double, 3>> junction_jumps(const ContactSet& set, std::span<const std::int32_t> displacement_dofs,
                                                  Vec u, MPI_Comm comm);

/// Per constraint of `set` its contact pressure (> 0 pressing), -sign
/// R'[dof] / lumped measure, from the contact force R' = T^-T (A x - b)
/// (its multiplier, ContactSolver::contact_force) at the constraints' DOFs
/// `dofs` (this rank's).
std::vector<double> contact_pressures(const ContactSet& set, std::span<const std::int32_t> dofs,
                                      const PetscScalar* force);

/// @brief The output fields of the contact: each contact node's pressure,
/// and 1 where it is on its foundation.
struct ContactFields
{
  dolfinx::fem::Function<double>& pressure;
  dolfinx::fem::Function<double>& active;
};

/// The contact state of a measurement; fills the output fields (collective).
ContactState contact_state(const ContactMeasurement& m, ContactFields out, MPI_Comm comm);

/// Each fault pair's contact traction (>= 0 pressing) by its fault's name
/// and + node (where faults meet, a node is the + node of several): what a
/// fault's cells average into their effective normal stress
/// (FaultAperture::cell_means).
std::map<std::pair<std::string, std::int64_t>, double> pair_tractions(const ContactState& state);

/// @brief The contact active set of a displacement: the flag of each
/// contact DOF this rank owns (on the foundation to round-off) and the
/// number of active nodes on all ranks. Two sets of one run compare flag
/// by flag (same_active_set): equal counts can hide nodes that open while
/// as many close elsewhere.
struct ActiveSet
{
  std::vector<std::int8_t> flags; // this rank's contact DOFs
  int nodes = 0;                  // active nodes on all ranks
};

/// Whether a and b, two active sets on one partition, hold the same nodes
/// on every rank (collective over `comm`).
bool same_active_set(const ActiveSet& a, const ActiveSet& b, MPI_Comm comm);

} // namespace biotcontact
