// coupling.fallback's monolithic scheme: the scheme that solves a step the
// single-rate split failed at, beside the split's, on the same mesh.
#pragma once

#include "assembly/problem.h"
#include "coupling/scheme.h"

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

} // namespace biotcontact
