#include "contact/locate_contact.h"

#include "contact/fault_pair.h"
#include "contact/foundation_pair.h"

#include <dolfinx/fem/utils.h>

namespace biotcontact
{
using namespace dolfinx;

ContactSet locate_contact(const Scene& scene, const Domain& domain, const CompiledForms& forms,
                          std::shared_ptr<const fem::FunctionSpace> V)
{
  ContactSet c;
  c.dim = domain.dim();
  c.output_space = std::make_shared<fem::FunctionSpace>(V->sub({0})->collapse().first);
  c.dof_offset = V->dofmap()->index_map_bs() * V->dofmap()->index_map->local_range()[0];
  std::string error; // the first bad input on this rank
  add_foundation_pairs(scene, domain, forms, V, c, error);
  add_fault_pairs(scene, domain, forms, V, c, error);
  agree_on_error(error, domain.mesh->comm());
  return c;
}

void check_contact(const Scene& scene, const Domain& domain)
{
  const CompiledForms& forms = compiled_forms(domain.mesh->topology().cell_type());
  auto V = std::make_shared<fem::FunctionSpace>(fem::create_functionspace(forms.displacement_space, "v_0", domain.mesh));
  locate_contact(scene, domain, forms, V);
}

} // namespace biotcontact
