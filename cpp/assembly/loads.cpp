#include "assembly/loads.h"

#include "assembly/linear_algebra.h"
#include "assembly/parameters.h"

namespace biotcontact
{
using namespace dolfinx;

Loads::Loads(std::shared_ptr<const common::IndexMap> map, int bs,
             std::function<void(la::Vector<double>&, double)> finish)
    : _map(std::move(map)), _bs(bs), _finish(std::move(finish))
{
}

void Loads::add(std::shared_ptr<const fem::Form<double>> form, std::shared_ptr<fem::Function<double>> data,
                std::vector<Expression> expressions)
{
  bool time_dependent = false;
  for (const Expression& e : expressions)
    time_dependent = time_dependent or e.depends_on_time();
  add(std::move(form), std::move(data),
      [expressions = std::move(expressions)](fem::Function<double>& f, double t) { interpolate(f, expressions, t); },
      time_dependent);
}

void Loads::add(std::shared_ptr<const fem::Form<double>> form, std::shared_ptr<fem::Function<double>> data,
                std::function<void(fem::Function<double>&, double)> fill, bool time_dependent)
{
  _time_dependent = _time_dependent or time_dependent;
  _terms.push_back({std::move(form), std::move(data), std::move(fill)});
}

void Loads::add_boundary(
    const Domain& domain, const std::string& name,
    const std::function<std::shared_ptr<const fem::Form<double>>(const mesh::MeshTags<std::int32_t>*)>& make,
    std::shared_ptr<fem::Function<double>> data, std::vector<Expression> expressions)
{
  add_on_facets(domain.marker(name), make, std::move(data), std::move(expressions));
}

void Loads::add_on_facets(
    std::shared_ptr<const mesh::MeshTags<std::int32_t>> marker,
    const std::function<std::shared_ptr<const fem::Form<double>>(const mesh::MeshTags<std::int32_t>*)>& make,
    std::shared_ptr<fem::Function<double>> data, std::vector<Expression> expressions)
{
  _markers.push_back(std::move(marker));
  add(make(_markers.back().get()), std::move(data), std::move(expressions));
}

const la::Vector<double>& Loads::at(double t)
{
  for (const auto& [time, b] : _vectors)
    if (time == t or !_time_dependent)
      return *b;
  // The oldest vector is reused once keep() are held.
  std::unique_ptr<la::Vector<double>> vector;
  if (_vectors.size() >= _keep)
  {
    vector = std::move(_vectors.front().second);
    _vectors.pop_front();
    vector->set(0.0);
  }
  else
    vector = std::make_unique<la::Vector<double>>(_map, _bs);
  _vectors.emplace_back(t, std::move(vector));
  la::Vector<double>& b = *_vectors.back().second;
  for (const Term& term : _terms)
  {
    if (term.data)
      term.fill(*term.data, t);
    add_vector(b, *term.form);
  }
  _finish(b, t);
  return b;
}

} // namespace biotcontact
