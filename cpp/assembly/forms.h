// The FFCx-compiled forms of forms/biot.py, for the cell type of a mesh.
#pragma once

#include "assembly/parameters.h"

#include <dolfinx/fem/Form.h>
#include <dolfinx/fem/FunctionSpace.h>
#include <dolfinx/mesh/MeshTags.h>
#include <dolfinx/mesh/cell_types.h>
#include <memory>
#include <ufcx.h>

namespace biotcontact
{

/// One compiled form per entry of forms/biot.py:FORM_NAMES.
struct CompiledForms
{
  ufcx_form* a_elastic;
  ufcx_form* a_pressure_load;
  ufcx_form* L_body_force;
  ufcx_form* L_traction;
  ufcx_form* L_lumped_boundary;
  ufcx_form* a_flow;
  ufcx_form* a_flow_storage;
  ufcx_form* a_flow_stabilisation;
  ufcx_form* a_flow_displacement;
  ufcx_form* L_flow_source;
  ufcx_form* L_flow_pressure;
  ufcx_form* L_flow_gravity;
  ufcx_form* a_divergence;
  ufcx_form* L_cell_volume;
  ufcx_form* L_sigma_v;
  ufcx_form* M_pressure_error;
  ufcx_form* M_pressure_reference;
  ufcx_form* M_displacement_error;
  ufcx_form* M_displacement_reference;
  ufcx_form* a_monolithic;
  ufcx_form* a_monolithic_preconditioner;
  ufcx_form* L_monolithic_history;
  ufcx_form* L_monolithic_body_force;
  ufcx_form* L_monolithic_traction;
  ufcx_form* L_monolithic_source;
  ufcx_form* L_monolithic_pressure;
  ufcx_form* L_monolithic_gravity;

  // Function-space factories of the forms in which each space appears.
  using SpaceFactory = ufcx_function_space* (*)(const char*);
  SpaceFactory displacement_space;           // "u" of a_elastic (P1 vector)
  SpaceFactory flow_space;                   // "v_0" (RT x P0), "resistivity" of a_flow
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
