#include "assembly/forms.h"

#include "biot_tetrahedron.h"
#include "biot_triangle.h"
#include <dolfinx/fem/utils.h>
#include <stdexcept>

namespace biotcontact
{

// FFCx names every form form_biot_<cell>_<name> and the space factories
// of a form functionspace_form_biot_<cell>_<name>.
#define BIOTCONTACT_SPACES(forms, cell)                                                        \
  forms.displacement_space = functionspace_form_biot_##cell##_a_elastic;                      \
  forms.flow_space = functionspace_form_biot_##cell##_a_flow;                                 \
  forms.material_space = functionspace_form_biot_##cell##_a_elastic;                          \
  forms.cell_vector_space = functionspace_form_biot_##cell##_L_body_force_cells;              \
  forms.data_space = functionspace_form_biot_##cell##_L_flow_source;                          \
  forms.pressure_reference_space = functionspace_form_biot_##cell##_M_pressure_error;         \
  forms.displacement_reference_space = functionspace_form_biot_##cell##_M_displacement_error; \
  forms.monolithic_space = functionspace_form_biot_##cell##_a_monolithic;

namespace
{
CompiledForms triangle_forms()
{
  CompiledForms forms;
#define BIOTCONTACT_TRIANGLE(name) forms.name = form_biot_triangle_##name;
  BIOTCONTACT_FORMS(BIOTCONTACT_TRIANGLE)
  BIOTCONTACT_SPACES(forms, triangle)
  return forms;
}

CompiledForms tetrahedron_forms()
{
  CompiledForms forms;
#define BIOTCONTACT_TETRAHEDRON(name) forms.name = form_biot_tetrahedron_##name;
  BIOTCONTACT_FORMS(BIOTCONTACT_TETRAHEDRON)
  BIOTCONTACT_SPACES(forms, tetrahedron)
  return forms;
}
} // namespace

const CompiledForms& compiled_forms(dolfinx::mesh::CellType cell)
{
  static const CompiledForms triangle = triangle_forms();
  static const CompiledForms tetrahedron = tetrahedron_forms();
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
