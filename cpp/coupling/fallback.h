// coupling.fallback's monolithic scheme: the scheme that solves a step the
// split failed at, beside the split's, on the same mesh, and what it tells
// the run.
#pragma once

#include "assembly/problem.h"
#include "coupling/coupling.h"
#include "coupling/scheme.h"

#include <functional>
#include <memory>
#include <optional>

namespace biotcontact
{

/// @brief The monolithic scheme of a split run's scene, made at the
/// split's first failed step: the scene with coupling.scheme =
/// "monolithic" and what set-up derives from it (its own constants: each
/// scheme sets its dt), on the split's domain and forms. The run moves the
/// state between the two schemes (output/checkpoint.h, restore_run_state).
struct MonolithicFallback
{
  explicit MonolithicFallback(const Problem& split);

  const Scene scene;
  Materials materials;
  Parameters parameters;
  Constants constants;
  std::optional<Problem> problem;
  std::unique_ptr<Scheme> scheme;
};

/// @brief The split's failed step as the monolithic scheme solves it: its
/// number, the time reached and the iterations of its steps.
struct SolvedStep
{
  int step = 0;
  double t = 0;
  int iterations = 0;
};

/// The observer of the monolithic scheme's steps for the split's failed
/// step `solved` ending at `end`, from the run's observer `split`: they
/// fill `solved` and stop at or past `end`; their rows in iterations.csv
/// carry the step's number, their retries (time.retry, which count their
/// own fine steps) name the scheme; each fine step before `end` is written
/// by `write_flow` (a multirate window's), the last left to the run with
/// the mechanics.
WindowObserver fallback_observer(const WindowObserver& split, SolvedStep& solved, double end,
                                 const std::function<void(double)>& write_flow);

} // namespace biotcontact
