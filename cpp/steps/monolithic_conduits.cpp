#include "steps/monolithic_conduits.h"

#include "assembly/linear_algebra.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <dolfinx/fem/assembler.h>

namespace biotcontact
{
using namespace dolfinx;

MonolithicConduits::MonolithicConduits(const Problem& problem, const MixedSpace& space) : _problem(problem)
{
  auto faults = std::make_unique<ConduitFaults>(problem.scene, problem.domain, *space.X.sub({1}), space.flux);
  if (!*faults)
    return;
  _faults = std::move(faults);
  _faults->with_implicit_openings();
  _pressure = _faults->initial_pressure(problem.scene.flow->initial_pressure);
  _pressure_old = _pressure;
  _aperture = std::make_unique<FaultAperture>(problem.scene, problem.domain, space.V);
  Mat R = placement(space.V, space.V_to_X, space.X);
  MatMatMult(_aperture->jump(), R, MAT_INITIAL_MATRIX, PETSC_DEFAULT, &_J);
  MatDestroy(&R);
  MatCreateVecs(_J, nullptr, &_cells);
  _rows = owned_size(space.X);
  make_load_rows(space);
}

/// E = B_z^T - J^T |k|, zero on the Dirichlet rows (whose equations are
/// x_i = g_i alone): neither the faces nor J change with the apertures.
void MonolithicConduits::make_load_rows(const MixedSpace& space)
{
  la::Vector<double> ones(space.X.dofmap()->index_map, 1);
  std::fill(ones.mutable_array().begin(), ones.mutable_array().end(), 1.0);
  fem::set_bc(ones.mutable_array(), space.bcs, 0.0);
  Vec no_bcs = nullptr, measures = nullptr;
  MatCreateVecs(_J, &no_bcs, nullptr);
  la::petsc::Vector from = wrap(ones);
  VecCopy(from.vec(), no_bcs);
  VecDuplicate(_cells, &measures);
  const std::vector<double>& m = _aperture->measures();
  for (std::size_t k = 0; k < m.size(); ++k)
    VecSetValue(measures, static_cast<PetscInt>(k), -m[k], INSERT_VALUES); // every cell on the last rank
  VecAssemblyBegin(measures);
  VecAssemblyEnd(measures);
  Mat B_z = _faults->exchange(_rows), Jt = nullptr;
  MatTranspose(B_z, MAT_INITIAL_MATRIX, &_E);
  MatTranspose(_J, MAT_INITIAL_MATRIX, &Jt);
  MatDiagonalScale(Jt, nullptr, measures);
  MatAXPY(_E, 1.0, Jt, DIFFERENT_NONZERO_PATTERN);
  MatDiagonalScale(_E, no_bcs, nullptr);
  MatDestroy(&Jt);
  MatDestroy(&B_z);
  VecDestroy(&measures);
  VecDestroy(&no_bcs);
}

MonolithicConduits::~MonolithicConduits()
{
  MatDestroy(&_J);
  MatDestroy(&_E);
  VecDestroy(&_cells);
}

bool MonolithicConduits::has_closure() const
{
  return std::any_of(_problem.scene.faults.begin(), _problem.scene.faults.end(),
                     [](const auto& f) { return f.second.flow == FaultFlow::conduit and f.second.closure; });
}

double MonolithicConduits::dt() const { return _problem.constants.at("dt")->value[0]; }

void MonolithicConduits::append(System& system) const
{
  Mat B_z = _faults->exchange(_rows), E = nullptr;
  MatDuplicate(_E, MAT_COPY_VALUES, &E); // the System takes it
  // B = B_z - (|k|/dt) O J: every entry of J kept, zero where closed, so
  // that the structure stays as cells open and close.
  Mat B = nullptr;
  MatDuplicate(_J, MAT_COPY_VALUES, &B);
  const std::vector<double> rates = _faults->opening_rates(dt(), _pressure_old, _pressure);
  Vec factors = nullptr;
  VecDuplicate(_cells, &factors);
  double* r = nullptr;
  VecGetArray(factors, &r);
  std::copy(rates.begin(), rates.end(), r);
  VecRestoreArray(factors, &r);
  MatDiagonalScale(B, factors, nullptr);
  MatAXPY(B, 1.0, B_z, DIFFERENT_NONZERO_PATTERN);
  VecDestroy(&factors);
  MatDestroy(&B_z);
  system.append({B, _faults->operator_matrix(dt()), _faults->face_resistance(),
                 std::vector<double>(_faults->owned(), 0.0), _pressure, E});
}

void MonolithicConduits::begin_step(System& system, la::Vector<double>& u, std::span<const double> s_n)
{
  _faults->begin_step();
  _pressure_old = _pressure;
  _faults->set_openings(_aperture->opening(u), s_n);
  append(system);
}

void MonolithicConduits::load(System& system, la::Vector<double>& x, double t)
{
  AppendedUnknowns& appended = system.appended();
  _faults->load({t, dt(), 1, 1}, _pressure_old, _pressure, appended.b);
  // The open cells' volume at u^i, which B's rows move to u^{i+1}.
  la::petsc::Vector X = wrap(x);
  MatMult(_J, X.vec(), _cells);
  const std::vector<double> rates = _faults->opening_rates(dt(), _pressure_old, _pressure);
  const double* Ju = nullptr;
  VecGetArrayRead(_cells, &Ju);
  for (std::size_t k = 0; k < rates.size(); ++k)
    appended.b[k] += rates[k] * Ju[k];
  VecRestoreArrayRead(_cells, &Ju);
  appended.x = _pressure;
}

bool MonolithicConduits::update(System& system, la::Vector<double>& u, std::span<const double> s_n)
{
  const std::vector<double> before = _pressure;
  _pressure = system.appended().x;
  _faults->set_openings(_aperture->opening(u), s_n);
  std::array<double, 2> moved{0, 0}; // max |p_f - p_f^i|, max |p_f|
  for (std::size_t k = 0; k < before.size(); ++k)
    moved = {std::max(moved[0], std::abs(_pressure[k] - before[k])), std::max(moved[1], std::abs(_pressure[k]))};
  MPI_Allreduce(MPI_IN_PLACE, moved.data(), 2, MPI_DOUBLE, MPI_MAX, _problem.domain.mesh->comm());
  const double tolerance = _problem.scene.coupling->tolerance;
  const bool converged = _faults->aperture_change() <= tolerance and moved[0] <= tolerance * moved[1];
  if (!converged) // the next iterate's rows: its apertures, and B's Newton term at its p_f
    append(system);
  return converged;
}

std::vector<double> MonolithicConduits::normal_stress(const ContactState& state) const
{
  return _aperture->cell_means(pair_tractions(state));
}

void MonolithicConduits::accept(std::span<const double> x, double t)
{
  const FineStep step{t, dt(), 1, 1};
  _faults->add_volumes(_faults->step_volumes(x, _pressure, _pressure_old, step), step);
}

std::string MonolithicConduits::unbalanced(std::span<const double> x, double t, double rock_flux) const
{
  return _faults->unbalanced(_faults->step_volumes(x, _pressure, _pressure_old, {t, dt(), 1, 1}), rock_flux);
}

std::vector<double> MonolithicConduits::cell_values(std::span<const double> x, double t) const
{
  return _faults->cell_values(x, _pressure, t);
}

void MonolithicConduits::keep(std::map<std::string, std::vector<double>>& arrays) const
{
  arrays.merge(_faults->arrays(_pressure));
}

void MonolithicConduits::restore(const std::map<std::string, std::vector<double>>& arrays)
{
  _faults->restore_arrays(arrays, _pressure);
}

} // namespace biotcontact
