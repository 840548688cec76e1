// The problem a run solves, made once in set-up and read by every step and
// scheme: the scene, its mesh and named boundaries, the forms compiled for
// its cell type, the materials of its cells, the derived parameters and the
// constants of the forms. The parts travel together; no signature lists
// them one by one.
#pragma once

#include "assembly/forms.h"
#include "assembly/materials.h"
#include "assembly/parameters.h"
#include "domain/domain.h"
#include "scene/scene.h"

namespace biotcontact
{

/// @brief The scene, domain, forms, materials, parameters and constants of
/// a run, by reference: set-up owns them, steps and schemes hold this.
struct Problem
{
  const Scene& scene;
  const Domain& domain;
  const CompiledForms& forms;
  /// Cell by cell (materials.h); the second pass of "multirate-two-pass"
  /// holds a problem whose materials have L = 0.
  const Materials& materials;
  /// Of the top-level material; gamma the largest of any cell.
  const Parameters& parameters;
  const Constants& constants;

  /// The same problem with other materials.
  Problem with_materials(const Materials& other) const { return {scene, domain, forms, other, parameters, constants}; }
};

} // namespace biotcontact
