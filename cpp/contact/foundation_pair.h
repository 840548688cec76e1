// The contact pair of a face against a rigid foundation (alg. "Mechanics
// with frictionless Signorini contact"): each node of a contact boundary
// and each foundation it touches, u.nu_F <= g_a. A node on two boundaries
// with the same normal holds one constraint (the smaller gap), with
// different normals two (the apex of a groove); normals along coordinate
// axes bound a component of u itself, others go through the node's change
// of variables (change_of_variables.h).
#pragma once

#include "contact/contact_set.h"
#include "scene/scene.h"

namespace biotcontact
{

/// Adds the constraints of the scene's contact boundaries at the nodes this
/// rank owns to c; the first bad input (a gap below 0, a normal that is
/// zero or not finite at a node, normals at a node that are not
/// independent, or one that is not perpendicular to a prescribed
/// displacement component of its node) goes into `error`, naming its key.
void add_foundation_pairs(const Scene& scene, const Domain& domain, const CompiledForms& forms,
                          std::shared_ptr<const dolfinx::fem::FunctionSpace> V, ContactSet& c, std::string& error);

} // namespace biotcontact
