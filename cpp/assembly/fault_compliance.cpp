#include "assembly/fault_compliance.h"

#include <algorithm>
#include <cmath>
#include <numeric>

namespace biotcontact
{

double softest_modulus(const Scene& scene)
{
  // E' = E/(1 - nu^2) = 4 G (lambda + G)/(lambda + 2 G)
  auto modulus = [](const MechanicsSpec& m) { return 4 * m.G * (m.lambda + m.G) / (m.lambda + 2 * m.G); };
  double E = modulus(*scene.mechanics);
  for (const auto& [name, r] : scene.regions)
    if (r.mechanics)
      E = std::min(E, modulus(*r.mechanics));
  return E;
}

double patch_compliance(double size, double modulus, int dim)
{
  return dim == 2 ? M_PI * (size / 2) / modulus : 16 * std::sqrt(size / M_PI) / (3 * M_PI * modulus);
}

double closure_aperture(const ClosureSpec& closure, double s_n)
{
  // V_m - V_m s/(K_ni V_m + s) written without the cancellation at large s.
  const double stiffness = closure.K_ni * closure.V_m;
  return closure.V_m * stiffness / (stiffness + std::max(s_n, 0.0));
}

double closure_compliance(const ClosureSpec& closure, double s_n)
{
  const double stiffness = closure.K_ni * closure.V_m + std::max(s_n, 0.0);
  return closure.K_ni * closure.V_m * closure.V_m / (stiffness * stiffness);
}

std::vector<std::int64_t> open_patches(const std::vector<const FaultEdges*>& links, std::span<const char> open)
{
  // Union-find over the links between open cells; the roots numbered after.
  std::vector<std::int64_t> parent(open.size());
  std::iota(parent.begin(), parent.end(), 0);
  auto root = [&](std::int64_t k)
  {
    while (parent[k] != k)
      k = parent[k] = parent[parent[k]];
    return k;
  };
  for (const FaultEdges* edges : links)
    for (std::size_t e = 0; e < edges->size(); ++e)
      if (open[edges->cells[2 * e]] and open[edges->cells[2 * e + 1]])
        parent[root(edges->cells[2 * e])] = root(edges->cells[2 * e + 1]);
  std::vector<std::int64_t> patch(open.size(), -1), number(open.size(), -1);
  std::int64_t patches = 0;
  for (std::size_t k = 0; k < open.size(); ++k)
    if (open[k])
    {
      std::int64_t& n = number[root(k)];
      patch[k] = n < 0 ? (n = patches++) : n;
    }
  return patch;
}

} // namespace biotcontact
