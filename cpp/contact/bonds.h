// The bonds of the cohesive constraints (contact_law.h, "the bond"): which
// break after a failed solve or an accepted step, and their names in a
// checkpoint. The contact solver (contact.h) keeps them as of now
// (ContactSet::bonded) and as of the last accepted step.
#pragma once

#include "assembly/petsc_error.h"
#include "contact/contact_set.h"

#include <mpi.h>
#include <span>
#include <vector>

namespace biotcontact
{

/// @brief A contact solve that failed on every path though the bonds its
/// clamped start pulled were broken: pairs the remaining bonds hold still
/// have no state (pulled while closed, overlapping while open), as where a
/// split's p_f, from the flow alone, passes a cohesive fault's normal
/// stress along its length.
struct BondFailure : SolverError
{
  using SolverError::SolverError;
};

/// A name of each constraint that no partition changes: the input index of
/// its node (a fault pair's + node) times 4, plus its place among the
/// constraints of that node (two or three foundations may meet there).
std::vector<std::int64_t> constraint_keys(const ContactSet& set);

/// Whether any contact boundary or fault of `set` has a cohesion.
bool cohesive(const ContactSet& set);

/// After a failed solve: breaks the bond of each cohesive frictional
/// constraint that `closed` (the VI's frictional constraints' flags in its
/// clamped start, closed_when_clamped; this rank's from position `first`;
/// none before a clamped start: all hold) does not hold closed; whether
/// any broke here.
bool break_pulled_bonds(ContactSet& set, std::span<const char> closed, std::size_t first);

/// At an accepted step: breaks the bond of each constraint not closed in
/// `closed` (per constraint, ActiveSet's flags); whether any broke here.
bool break_open_bonds(ContactSet& set, std::span<const signed char> closed);

/// The names (constraint_keys) of the cohesive constraints whose bond
/// `bonded` holds broken, every rank's, sorted (collective).
std::vector<double> broken_bond_names(const ContactSet& set, std::span<const char> bonded, MPI_Comm comm);

/// Per constraint, whether its bond holds when `broken` (sorted) names the
/// broken ones.
std::vector<char> bonds_from_names(const ContactSet& set, const std::vector<double>& broken);

} // namespace biotcontact
