// Pins on the contact's constraints (contact.h, ContactSolver::pin): a
// constraint pinned closed is held on its bound, one pinned open has none,
// as the fixed-stress split asks where its contact set cycles
// (coupling/pins.h). Twin: python_prototype/contact/contact_pins.py.
#include "contact/contact.h"

#include <algorithm>
#include <mpi.h>

namespace biotcontact
{

/// A pinned constraint contradicts its pin (ContactSolver::consistent_pins)
/// beyond this fraction of the displacement scale or the largest contact
/// pressure: the tolerance of SNES's "on a bound" (variational_inequality.h).
constexpr double pin_tolerance = 1e-8;

void ContactSolver::pin(std::vector<std::int8_t> pins)
{
  int local = !pins.empty(), any = 0;
  MPI_Allreduce(&local, &any, 1, MPI_INT, MPI_MAX, _comm);
  _pinned = any;
  _pins = std::move(pins);
  _pins.resize(_dofs.size(), 0);
}

std::vector<std::int8_t> ContactSolver::pins_in_vi() const
{
  if (!_schur)
    return _pins;
  std::vector<double> mine(contact_dofs().size(), 0.0), all(_schur->size());
  std::copy(_pins.begin(), _pins.end(), mine.begin());
  _schur->gather(mine.data(), all.data());
  std::vector<std::int8_t> pins;
  for (std::int32_t position : _vi->bounded())
    pins.push_back(static_cast<std::int8_t>(all[position]));
  return pins;
}

std::vector<std::int8_t> ContactSolver::consistent_pins(Vec x, Vec b)
{
  const std::vector<double> distance = distances(x);
  const double scale = displacement_scale(_set, _displacement_dofs, x, _comm);
  const Vec force = contact_force(x, b);
  const PetscScalar* R;
  check_petsc(VecGetArrayRead(force, &R), "contact solver: VecGetArrayRead of the contact force");
  const std::vector<double> pressure = contact_pressures(_set, _dofs, R);
  double local = 0, largest = 0;
  for (double p : pressure)
    local = std::max(local, p);
  check_petsc(VecRestoreArrayRead(force, &R), "contact solver: VecRestoreArrayRead of the contact force");
  MPI_Allreduce(&local, &largest, 1, MPI_DOUBLE, MPI_MAX, _comm);
  std::vector<std::int8_t> pins = _pins;
  for (std::size_t k = 0; k < pins.size(); ++k)
    if ((pins[k] < 0 and distance[k] < -pin_tolerance * scale)
        or (pins[k] > 0 and pressure[k] < -pin_tolerance * largest))
      pins[k] = static_cast<std::int8_t>(-pins[k]);
  return pins;
}

} // namespace biotcontact
