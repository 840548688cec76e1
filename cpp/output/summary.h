// summary.json: what a run computed and what it cost, whatever its end
// (docs/user-guide.md, "summary.json").
#pragma once

#include "assembly/problem.h"
#include "coupling/scheme.h"
#include "diagnostics/reference_errors.h"
#include "output/output.h"

#include <optional>
#include <string>

namespace biotcontact
{

/// @brief How a run ended and what it said on the way.
struct RunOutcome
{
  std::string failure;        // empty when nothing failed
  int signal = 0;             // the interruption that ended it
  double completed_time = 0;  // of its last completed step
  std::string left_out, warnings;
  double wall_time = 0;       // s
  double output_time = 0;     // s spent writing
  int ranks = 1;         // started
  int working_ranks = 1; // holding the mesh (domain/working_ranks.h)
};

/// @brief Everything summary.json reports on.
struct SummaryInput
{
  const Problem& problem;
  const Scheme& scheme;
  const CouplingReport& report;
  const TimeGrid& grid;
  const ContactState& contact;       // at the last mechanics output
  std::optional<ReferenceErrors> errors; // against the scene's closed form
  const Scheme* fallback = nullptr;      // the monolithic scheme of coupling.fallback, once it solved a step
};

/// The summary: the scheme, sizes, counts, contraction measures, solvers,
/// timings, contact and closed-form errors of the run.
Json run_summary(const SummaryInput& in, const RunOutcome& outcome);

} // namespace biotcontact
