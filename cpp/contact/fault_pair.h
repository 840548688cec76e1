// The contact pair of a fault: each node on its + face against its twin on
// the - face (theory.md, "Faults"). With n the fault's unit normal into the
// + side and g0 its initial aperture, the faces may open but not overlap:
// [u].n + g0 >= 0, [u] = u+ - u-, a Signorini constraint on the jump,
// nu.[u] <= g0 with nu = -n. The change of variables of the pair
// (change_of_variables.h, pair_change_of_variables) makes nu.[u] one
// unknown, in the + node's first row, bounded by g0; the VI solver treats it
// as a node on a rigid foundation, its multiplier the contact traction on
// the faces. Where faults cross or end on one another (a junction) the pairs
// there share one block, each pair's nu.[u] in a row of its + node
// (junction_change_of_variables).
#pragma once

#include "contact/contact_set.h"
#include "scene/scene.h"

namespace biotcontact
{

/// Adds the constraints of every fault pair whose + node this rank owns to
/// c, with the pair's block of the change of variables; the first bad
/// input (a gap below 0, a normal that mixes a prescribed displacement
/// component, a junction that cannot be posed or is held by a prescribed
/// displacement) goes into `error`, naming its key (collective).
void add_fault_pairs(const Scene& scene, const Domain& domain, const CompiledForms& forms,
                     std::shared_ptr<const dolfinx::fem::FunctionSpace> V, ContactSet& c, std::string& error);

} // namespace biotcontact
