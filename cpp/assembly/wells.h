// Wells: point (2D) or vertical line (3D) sources and sinks in the cells
// that contain them, added to the flow's right-hand side.
#pragma once

#include "domain/domain.h"

#include <dolfinx/fem/FunctionSpace.h>
#include <span>
#include <vector>

namespace biotcontact
{

/// @brief One well in the mass balance: its rate R(t) spread over its
/// cells, the source R share_K / |K| on cell K, whose integral against the
/// cell's P0 test function is R share_K in the cell's pressure row.
struct WellSource
{
  const Expression* rate = nullptr;
  std::vector<std::int32_t> rows; // the pressure rows of its owned cells in the (mixed) vector
  std::vector<double> shares;
};

/// The wells of a scene into the rock, in a vector whose pressure part (the
/// P0 space Q) sits at `Q_to_vector` (a well into a conduit fault is
/// fault_flow.h's).
std::vector<WellSource> well_sources(const Scene& scene, const Domain& domain, const dolfinx::fem::FunctionSpace& Q,
                                     std::span<const std::int32_t> Q_to_vector);

/// b -= R(t) share in each well cell's row: forms/biot.py writes the mass
/// balance times -1, its source term as -(Q, th).
void add_wells(const std::vector<WellSource>& wells, double t, std::span<double> b);

/// Whether any well's rate changes in time.
bool depends_on_time(const std::vector<WellSource>& wells);

} // namespace biotcontact
