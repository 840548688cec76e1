// The faults' seismic moments step by step (docs/user-guide.md, "Faults":
// M0 = sum over a fault's pairs of G |slip increment| times their lumped
// measure): what the mechanics and the monolithic step record at each
// accepted step, keep in checkpoints and give the summary. The prototype's
// twin is python_prototype/steps/seismic_moments.py.
#pragma once

#include "contact/contact_state.h"

#include <map>
#include <string>
#include <vector>

namespace biotcontact
{

/// @brief The faults' seismic moments step by step (FaultSummary::moment):
/// per accepted step its time, then the moment of each of `names`.
struct SeismicMoments
{
  std::vector<std::string> names;
  std::vector<double> steps;
};

/// An empty record of the faults of `set` (its boundaries that are faults).
SeismicMoments moments_of(const ContactSet& set);

/// Adds the step accepted at t, each fault's moment of `state` (its
/// contact state at t; collective where it was computed).
void record_moments(SeismicMoments& moments, double t, const ContactState& state);

/// Puts the record into a checkpoint's arrays, "seismic_moments" (nothing
/// while it is empty), and takes it back.
void keep_moments(const SeismicMoments& moments, std::map<std::string, std::vector<double>>& arrays);
void restore_moments(SeismicMoments& moments, const std::map<std::string, std::vector<double>>& arrays);

} // namespace biotcontact
