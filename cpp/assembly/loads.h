// The loads of a step: the right-hand-side terms that change with time only
// (body force, tractions, source, boundary pressures, gravity), assembled
// into one vector per time and kept for the last few times.
#pragma once

#include "assembly/forms.h"
#include "domain/domain.h"
#include "scene/expression.h"

#include <deque>
#include <dolfinx/fem/Form.h>
#include <dolfinx/fem/Function.h>
#include <dolfinx/la/Vector.h>
#include <functional>
#include <memory>
#include <vector>

namespace biotcontact
{

/// @brief The time-dependent right-hand side of a step, with its time cache.
///
/// Each term is a linear form whose data coefficient is interpolated from
/// the scene's expressions at t before it is assembled (a term without
/// data, such as gravity, is assembled as it is). Terms are summed in the
/// order they were added. The vector of a time is assembled once and kept
/// for the last keep() times (a multirate iteration visits the q fine times
/// of its window again); loads that do not depend on time are assembled once
/// per run.
class Loads
{
public:
  /// `finish(b, t)` completes an assembled vector (ghost accumulation,
  /// lifting and Dirichlet values at t), for the step's system.
  Loads(std::shared_ptr<const dolfinx::common::IndexMap> map, int bs,
        std::function<void(dolfinx::la::Vector<double>&, double)> finish);

  /// Adds the term `form`, whose coefficient `data` is interpolated from
  /// `expressions` (one per component) at each time; data may be null.
  void add(std::shared_ptr<const dolfinx::fem::Form<double>> form,
           std::shared_ptr<dolfinx::fem::Function<double>> data = nullptr, std::vector<Expression> expressions = {});

  /// Adds the term `form`, whose coefficient `data` is set by `fill(data, t)`
  /// at each time (when `time_dependent`, else once).
  void add(std::shared_ptr<const dolfinx::fem::Form<double>> form, std::shared_ptr<dolfinx::fem::Function<double>> data,
           std::function<void(dolfinx::fem::Function<double>&, double)> fill, bool time_dependent);

  /// Adds the term of a load on boundary `name`: `make(marker)` builds its
  /// form with the ds(1) integrals on that boundary's facets.
  void add_boundary(const Domain& domain, const std::string& name,
                    const std::function<std::shared_ptr<const dolfinx::fem::Form<double>>(
                        const dolfinx::mesh::MeshTags<std::int32_t>*)>& make,
                    std::shared_ptr<dolfinx::fem::Function<double>> data, std::vector<Expression> expressions);

  /// Adds the term of a load on the facets `marker` marks: `make(marker)`
  /// builds its form.
  void add_on_facets(std::shared_ptr<const dolfinx::mesh::MeshTags<std::int32_t>> marker,
                     const std::function<std::shared_ptr<const dolfinx::fem::Form<double>>(
                         const dolfinx::mesh::MeshTags<std::int32_t>*)>& make,
                     std::shared_ptr<dolfinx::fem::Function<double>> data, std::vector<Expression> expressions);

  /// Something else of the step's right-hand side depends on time (Dirichlet values).
  void depends_on_time(bool dependence) { _time_dependent = _time_dependent or dependence; }

  /// Keeps the vectors of the last `times` times (1 by default).
  void keep(int times) { _keep = static_cast<std::size_t>(std::max(times, 1)); }

  /// The assembled loads at time t.
  const dolfinx::la::Vector<double>& at(double t);

private:
  struct Term
  {
    std::shared_ptr<const dolfinx::fem::Form<double>> form;
    std::shared_ptr<dolfinx::fem::Function<double>> data;
    std::function<void(dolfinx::fem::Function<double>&, double)> fill; // of data at t
  };
  std::shared_ptr<const dolfinx::common::IndexMap> _map;
  int _bs;
  std::function<void(dolfinx::la::Vector<double>&, double)> _finish;
  std::vector<Term> _terms;
  std::vector<std::shared_ptr<const dolfinx::mesh::MeshTags<std::int32_t>>> _markers;
  bool _time_dependent = false;
  std::size_t _keep = 1;
  std::deque<std::pair<double, std::unique_ptr<dolfinx::la::Vector<double>>>> _vectors; // oldest first
};

} // namespace biotcontact
