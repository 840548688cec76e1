// The errors of a run against its scene's closed form ([reference]:
// Terzaghi or Mandel, closed_form.h) at the final time, for summary.json.
#pragma once

#include "assembly/problem.h"

#include <dolfinx/fem/Function.h>
#include <memory>
#include <optional>

namespace biotcontact
{

/// @brief Relative L2 errors of pressure and displacement at `time`, and
/// for Terzaghi the settlement of the top against the exact one.
struct ReferenceErrors
{
  double time = 0, pressure_rel_l2 = 0, displacement_rel_l2 = 0;
  struct Settlement
  {
    double computed, exact, relative;
  };
  std::optional<Settlement> settlement;
};

/// The errors of (u, p) at the scene's end time against problem.scene's
/// reference (which it must have); the closed form is interpolated into P2.
ReferenceErrors reference_errors(const Problem& problem, std::shared_ptr<const dolfinx::fem::Function<double>> u,
                                 std::shared_ptr<const dolfinx::fem::Function<double>> p);

} // namespace biotcontact
