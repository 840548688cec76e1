#include "assembly/forms.h"

#include "biot_tetrahedron.h"
#include "biot_triangle.h"
#include <dolfinx/fem/utils.h>
#include <stdexcept>

namespace biotcontact
{

// FFCx names every form form_<file>_<name>; the table is spelled out once
// here for both compilations of forms/biot.py.
#define BIOTCONTACT_FORMS(cell)                             \
  CompiledForms                                             \
  {                                                         \
    form_biot_##cell##_a_elastic,                           \
    form_biot_##cell##_a_pressure_load,                     \
    form_biot_##cell##_L_body_force,                        \
    form_biot_##cell##_L_traction,                          \
    form_biot_##cell##_L_lumped_boundary,                   \
    form_biot_##cell##_a_flow,                              \
    form_biot_##cell##_a_flow_storage,                      \
    form_biot_##cell##_a_flow_stabilisation,                \
    form_biot_##cell##_a_flow_displacement,                 \
    form_biot_##cell##_L_flow_source,                       \
    form_biot_##cell##_L_flow_pressure,                     \
    form_biot_##cell##_L_flow_gravity,                      \
    form_biot_##cell##_a_divergence,                        \
    form_biot_##cell##_L_cell_volume,                       \
    form_biot_##cell##_L_sigma_v,                           \
    form_biot_##cell##_M_pressure_error,                    \
    form_biot_##cell##_M_pressure_reference,                \
    form_biot_##cell##_M_displacement_error,                \
    form_biot_##cell##_M_displacement_reference,            \
    form_biot_##cell##_a_monolithic,                        \
    form_biot_##cell##_a_monolithic_preconditioner,         \
    form_biot_##cell##_L_monolithic_history,                \
    form_biot_##cell##_L_monolithic_body_force,             \
    form_biot_##cell##_L_monolithic_traction,               \
    form_biot_##cell##_L_monolithic_source,                 \
    form_biot_##cell##_L_monolithic_pressure,               \
    form_biot_##cell##_L_monolithic_gravity,                \
    functionspace_form_biot_##cell##_a_elastic,             \
    functionspace_form_biot_##cell##_a_flow,                \
    functionspace_form_biot_##cell##_L_flow_source,         \
    functionspace_form_biot_##cell##_M_pressure_error,      \
    functionspace_form_biot_##cell##_M_displacement_error,  \
    functionspace_form_biot_##cell##_a_monolithic           \
  }

const CompiledForms& compiled_forms(dolfinx::mesh::CellType cell)
{
  static const CompiledForms triangle = BIOTCONTACT_FORMS(triangle);
  static const CompiledForms tetrahedron = BIOTCONTACT_FORMS(tetrahedron);
  switch (cell)
  {
  case dolfinx::mesh::CellType::triangle:
    return triangle;
  case dolfinx::mesh::CellType::tetrahedron:
    return tetrahedron;
  default:
    throw std::runtime_error("biotcontact supports triangle and tetrahedron meshes only");
  }
}

std::shared_ptr<dolfinx::fem::Form<double>>
make_form(const ufcx_form* form, const std::vector<std::shared_ptr<const dolfinx::fem::FunctionSpace>>& spaces,
          const Coefficients& coefficients, const Constants& constants,
          const dolfinx::mesh::MeshTags<std::int32_t>* marker)
{
  std::map<dolfinx::fem::IntegralType, const dolfinx::mesh::MeshTags<std::int32_t>*> subdomains;
  if (marker)
    subdomains[dolfinx::fem::IntegralType::exterior_facet] = marker;
  return std::make_shared<dolfinx::fem::Form<double>>(
      dolfinx::fem::create_form<double>(*form, spaces, coefficients, constants, subdomains));
}

} // namespace biotcontact
