// Where the contact acts: the constraints of a scene's contact boundaries
// against their foundations (foundation_pair.h) and of its faults' node
// pairs (fault_pair.h), gathered into one ContactSet (contact_set.h).
#pragma once

#include "contact/contact_set.h"
#include "scene/scene.h"

#include <dolfinx/fem/FunctionSpace.h>
#include <memory>

namespace biotcontact
{

/// Finds the contact constraints of the scene: its contact boundaries
/// against their foundations (foundation_pair.h), then the faults' node
/// pairs (fault_pair.h). Throws SceneError, the same on every rank, for the
/// first bad input they find (collective).
ContactSet locate_contact(const Scene& scene, const Domain& domain, const CompiledForms& forms,
                          std::shared_ptr<const dolfinx::fem::FunctionSpace> V);

/// `check`'s look at the contact: the pairs made as a run makes them (a
/// fault's gap and normal, where it meets a foundation) in the scene's
/// displacement space; throws SceneError as locate_contact (collective).
void check_contact(const Scene& scene, const Domain& domain);

} // namespace biotcontact
