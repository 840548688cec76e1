// The FFCx-compiled forms of forms/biot.py, for the cell type of a mesh.
#pragma once

#include "assembly/parameters.h"
#include "biot_forms.h"

#include <dolfinx/fem/Form.h>
#include <dolfinx/fem/FunctionSpace.h>
#include <dolfinx/mesh/MeshTags.h>
#include <dolfinx/mesh/cell_types.h>
#include <memory>
#include <ufcx.h>

namespace biotcontact
{

/// @brief The compiled forms of forms/biot.py for one cell type, by name.
///
/// One field per form of biot.py (the list BIOTCONTACT_FORMS is generated
/// from it at build time), then the space factories the solver needs.
struct CompiledForms
{
#define BIOTCONTACT_DECLARE_FORM(name) ufcx_form* name;
  BIOTCONTACT_FORMS(BIOTCONTACT_DECLARE_FORM)
#undef BIOTCONTACT_DECLARE_FORM

  // Function-space factories of the forms in which each space appears.
  using SpaceFactory = ufcx_function_space* (*)(const char*);
  SpaceFactory displacement_space;           // "v_0" of a_elastic (P1 vector)
  SpaceFactory flow_space;                   // "v_0" (RT x P0), "resistivity" of a_flow
  SpaceFactory material_space;               // "G" of a_elastic (DG0): the cell-wise materials
  SpaceFactory cell_vector_space;            // "body_force_cells" of L_body_force_cells (DG0 vector)
  SpaceFactory data_space;                   // "source" of L_flow_source (P1)
  SpaceFactory pressure_reference_space;     // "p_reference" (P2)
  SpaceFactory displacement_reference_space; // "u_reference" (P2 vector)
  SpaceFactory monolithic_space;             // "v_0" (P1^d x RT x P0) of a_monolithic
};

/// The forms for triangles or tetrahedra; throws for other cells.
const CompiledForms& compiled_forms(dolfinx::mesh::CellType cell);

/// Binds a compiled form to its spaces, coefficients and constants (by UFL
/// name; extra entries are ignored). With a marker, the ds(1) integrals of
/// forms/biot.py run over the facets it tags.
std::shared_ptr<dolfinx::fem::Form<double>>
make_form(const ufcx_form* form, const std::vector<std::shared_ptr<const dolfinx::fem::FunctionSpace>>& spaces,
          const Coefficients& coefficients, const Constants& constants,
          const dolfinx::mesh::MeshTags<std::int32_t>* marker = nullptr);

} // namespace biotcontact
