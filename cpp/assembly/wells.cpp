#include "assembly/wells.h"

#include "domain/wells.h"

#include <dolfinx/fem/DofMap.h>

namespace biotcontact
{

std::vector<WellSource> well_sources(const Scene& scene, const Domain& domain, const dolfinx::fem::FunctionSpace& Q,
                                     std::span<const std::int32_t> Q_to_vector)
{
  std::vector<WellSource> wells;
  for (const auto& [name, w] : scene.wells)
  {
    if (!w.fault.empty())
      continue;
    const WellCells cells = locate_well(domain, w, "well." + name + ".position");
    WellSource source{&w.rate, {}, cells.shares};
    for (std::int32_t c : cells.cells)
      source.rows.push_back(Q_to_vector[Q.dofmap()->cell_dofs(c)[0]]);
    wells.push_back(std::move(source));
  }
  return wells;
}

void add_wells(const std::vector<WellSource>& wells, double t, std::span<double> b)
{
  for (const WellSource& w : wells)
  {
    const double rate = (*w.rate)(0, 0, 0, t);
    for (std::size_t k = 0; k < w.rows.size(); ++k)
      b[w.rows[k]] -= rate * w.shares[k];
  }
}

bool depends_on_time(const std::vector<WellSource>& wells)
{
  for (const WellSource& w : wells)
    if (w.rate->depends_on_time())
      return true;
  return false;
}

} // namespace biotcontact
