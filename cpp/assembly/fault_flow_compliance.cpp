// The fixed-stress terms of the conduit faults (ConduitFaults, fault_flow.h):
// each cell's L_f from the compliances of fault_compliance.h, the open
// patch's in the split and the closure's in closed cells, and the term the
// monolithic system's fixed-stress preconditioner gives the open cells.
// Twin: python_prototype/assembly/fault_flow_compliance.py.
#include "assembly/fault_compliance.h"
#include "assembly/fault_flow.h"

namespace biotcontact
{

std::vector<double> ConduitFaults::patch_compliances(const Conduit& c) const
{
  std::vector<char> stabilised(c.open.size());
  for (std::size_t k = 0; k < stabilised.size(); ++k)
    stabilised[k] = c.open[k] or c.open_before[k];
  const std::vector<std::int64_t> patch = open_patches({&c.cells->links, &c.cells->cut}, stabilised);
  std::vector<double> size(c.cells->size(), 0.0), L(c.cells->size(), -1.0);
  for (std::size_t k = 0; k < patch.size(); ++k)
    if (patch[k] >= 0)
      size[patch[k]] += c.cells->measures[k];
  for (std::size_t k = 0; k < patch.size(); ++k)
    if (patch[k] >= 0)
      L[k] = patch_compliance(size[patch[k]], c.modulus, _dim);
  return L;
}

void ConduitFaults::set_compliance(Conduit& c) const
{
  const std::vector<double> L = patch_compliances(c);
  for (std::size_t k = 0; k < L.size() and _stabilised; ++k)
    c.compliance[k] = _implicit and c.open[k] ? 0.0
                      : L[k] >= 0 and !_implicit ? L[k]
                      : c.closure               ? closure_compliance(*c.closure, c.traction[k])
                                                : 0.0;
}

std::vector<double> ConduitFaults::open_stabilisation(double dt) const
{
  std::vector<double> s(_rows.size(), 0.0);
  for (const Conduit& c : _conduits)
  {
    const std::vector<double> L = patch_compliances(c);
    for (std::size_t k = 0; k < L.size(); ++k)
      s[c.offset + k] = c.open[k] and L[k] > 0 ? L[k] * c.cells->measures[k] / dt : 0.0;
  }
  return _rows.entries(s);
}

std::vector<double> ConduitFaults::stabilisation(const Conduit& c, double dt) const
{
  std::vector<double> s(c.cells->size());
  for (std::size_t k = 0; k < s.size(); ++k)
    s[k] = c.compliance[k] * c.cells->measures[k] / dt;
  return s;
}

} // namespace biotcontact
