#include "output/fields.h"

#include "diagnostics/diagnostics.h"

#include <basix/finite-element.h>
#include <dolfinx/fem/utils.h>

namespace biotcontact
{
using namespace dolfinx;

namespace
{

/// The names ParaView shows.
void name_fields(Scheme& scheme)
{
  if (scheme.p)
    scheme.p->name = "pressure";
  if (scheme.u)
    scheme.u->name = "displacement";
  if (scheme.contact_pressure)
  {
    scheme.contact_pressure->name = "contact_pressure";
    scheme.contact_active->name = "contact_active";
  }
}

} // namespace

OutputFields::OutputFields(const Problem& problem, Scheme& scheme, Output& output, const double* resume_time)
    : _problem(problem), _output(output)
{
  read_from(scheme);
  const Domain& domain = problem.domain;
  const auto cell = mesh::cell_type_to_basix_type(domain.mesh->topology().cell_type());
  const basix::FiniteElement dg0 = basix::create_element(
      basix::element::family::P, cell, 0, basix::element::lagrange_variant::unset, true);
  if (scheme.p)
  {
    _flux = std::make_shared<fem::Function<double>>(
        std::make_shared<fem::FunctionSpace>(fem::create_functionspace(domain.mesh, dg0, domain.dim())));
    _flux->name = "flux";
  }
  if (!problem.scene.faults.empty() and problem.scene.write_xdmf)
    _faults = std::make_unique<FaultSeries>(domain.mesh->comm(), output.directory(), problem, resume_time);
  if (!scheme.u)
    return;
  auto Q0 = std::make_shared<fem::FunctionSpace>(fem::create_functionspace(domain.mesh, dg0, 1));
  _sigma_v = std::make_shared<fem::Function<double>>(Q0);
  _sigma_v->name = "sigma_v";
  if (!scheme.p and !scheme.given_pressure)
    _zero_pressure = std::make_shared<fem::Function<double>>(Q0);
}

void OutputFields::read_from(Scheme& scheme)
{
  name_fields(scheme);
  _scheme = &scheme;
}

void OutputFields::write_flow(double t)
{
  if (!_scheme->p)
    return;
  _output.write(*_scheme->p, t);
  _scheme->flux(*_flux);
  _output.write(*_flux, t);
  _fault_flow = _scheme->fault_flow(t);
  if (_faults and !_scheme->u) // else with the mechanics' fields
    _faults->write(ContactState{}, _fault_flow, t);
}

void OutputFields::write_mechanics(double t)
{
  contact = _scheme->contact_state();
  const std::shared_ptr<const fem::Function<double>> p
      = _scheme->p ? _scheme->p : _scheme->given_pressure ? _scheme->given_pressure : _zero_pressure;
  volumetric_stress(_problem.forms, _problem.constants, _problem.materials, _scheme->u, p, *_sigma_v);
  _output.write(*_scheme->u, t);
  _output.write(*_sigma_v, t);
  if (_scheme->contact_pressure)
  {
    _output.write(*_scheme->contact_pressure, t);
    _output.write(*_scheme->contact_active, t);
  }
  if (_faults)
    _faults->write(contact, _fault_flow, t);
}

} // namespace biotcontact
