#include "steps/monolithic_conduits.h"

#include "assembly/linear_algebra.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <dolfinx/fem/assembler.h>
#include <functional>
#include <limits>
#include <sstream>

namespace biotcontact
{
using namespace dolfinx;

namespace
{
/// check_petsc for the conduit faults' calls (VecSetValue runs once per
/// fault cell).
void check_conduits(PetscErrorCode code, const char* call) { check_petsc(code, "the conduit faults", call); }
} // namespace

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
  check_conduits(MatMatMult(_aperture->jump(), R, MAT_INITIAL_MATRIX, PETSC_DEFAULT, &_J), "MatMatMult of J and R");
  check_conduits(MatDestroy(&R), "MatDestroy of R");
  check_conduits(MatCreateVecs(_J, nullptr, &_cells), "MatCreateVecs of J");
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
  check_conduits(MatCreateVecs(_J, &no_bcs, nullptr), "MatCreateVecs of J");
  la::petsc::Vector from = wrap(ones);
  check_conduits(VecCopy(from.vec(), no_bcs), "VecCopy");
  check_conduits(VecDuplicate(_cells, &measures), "VecDuplicate");
  const std::vector<double>& m = _aperture->measures(); // this rank's cells, as J's rows
  double* entries = nullptr;
  check_conduits(VecGetArray(measures, &entries), "VecGetArray");
  std::transform(m.begin(), m.end(), entries, std::negate<>());
  check_conduits(VecRestoreArray(measures, &entries), "VecRestoreArray");
  Mat B_z = _faults->exchange(_rows), Jt = nullptr;
  check_conduits(MatTranspose(B_z, MAT_INITIAL_MATRIX, &_E), "MatTranspose of B_z");
  check_conduits(MatTranspose(_J, MAT_INITIAL_MATRIX, &Jt), "MatTranspose of J");
  check_conduits(MatDiagonalScale(Jt, nullptr, measures), "MatDiagonalScale of J^T");
  check_conduits(MatAXPY(_E, 1.0, Jt, DIFFERENT_NONZERO_PATTERN), "MatAXPY of E");
  check_conduits(MatDiagonalScale(_E, no_bcs, nullptr), "MatDiagonalScale of E");
  check_conduits(MatDestroy(&Jt), "MatDestroy of J^T");
  check_conduits(MatDestroy(&B_z), "MatDestroy of B_z");
  check_conduits(VecDestroy(&measures), "VecDestroy");
  check_conduits(VecDestroy(&no_bcs), "VecDestroy");
}

MonolithicConduits::~MonolithicConduits()
{
  warn_petsc(MatDestroy(&_J), "the conduit faults: MatDestroy");
  warn_petsc(MatDestroy(&_E), "the conduit faults: MatDestroy");
  warn_petsc(MatDestroy(&_G), "the conduit faults: MatDestroy");
  warn_petsc(VecDestroy(&_cells), "the conduit faults: VecDestroy");
}

bool MonolithicConduits::has_closure() const
{
  return std::any_of(_problem.scene.faults.begin(), _problem.scene.faults.end(),
                     [](const auto& f) { return f.second.flow == FaultFlow::conduit and f.second.closure; });
}

FineStep MonolithicConduits::step(double t) const
{
  return {t, _problem.constants.at("dt")->value[0], 1, 1, _derivative.coefficients()};
}

void MonolithicConduits::append(System& system)
{
  Mat B_z = _faults->exchange(_rows), E = nullptr;
  check_conduits(MatDuplicate(_E, MAT_COPY_VALUES, &E), "MatDuplicate of E"); // the System takes it
  // B = B_z + M J, M = G - (|k|/dt) O: Newton's term of the open cells'
  // transmissibilities (G at this iterate's p_f, kept for load's
  // right-hand side) and their opening rate (opening_rates); every entry of
  // J and G kept, zero where closed, so the structure stays as cells open
  // and close.
  check_conduits(MatDestroy(&_G), "MatDestroy of G");
  _G = _faults->flux_jacobian(_pressure, _time);
  Mat M = nullptr, B = nullptr;
  check_conduits(MatDuplicate(_G, MAT_COPY_VALUES, &M), "MatDuplicate of G");
  const std::vector<double> rates = _faults->opening_rates(step(0), _pressure_old, _pressure);
  Vec factors = nullptr;
  check_conduits(VecDuplicate(_cells, &factors), "VecDuplicate");
  double* r = nullptr;
  check_conduits(VecGetArray(factors, &r), "VecGetArray");
  std::copy(rates.begin(), rates.end(), r);
  check_conduits(VecRestoreArray(factors, &r), "VecRestoreArray");
  check_conduits(MatDiagonalSet(M, factors, ADD_VALUES), "MatDiagonalSet of M");
  check_conduits(MatMatMult(M, _J, MAT_INITIAL_MATRIX, PETSC_DEFAULT, &B), "MatMatMult of M and J");
  check_conduits(MatAXPY(B, 1.0, B_z, DIFFERENT_NONZERO_PATTERN), "MatAXPY of B");
  check_conduits(VecDestroy(&factors), "VecDestroy");
  check_conduits(MatDestroy(&M), "MatDestroy of M");
  check_conduits(MatDestroy(&B_z), "MatDestroy of B_z");
  // The fixed-stress preconditioner's C (iterative path) takes the split's
  // term -L_k/dt in the open cells, whose opening it leaves to the
  // mechanics (alg. "Single-rate ... (a)" on the fault).
  std::vector<double> L = _faults->open_stabilisation(step(0).dt);
  std::transform(L.begin(), L.end(), L.begin(), std::negate<>());
  system.append({B, _faults->operator_matrix(step(0).dt), _faults->face_resistance(),
                 std::vector<double>(_faults->owned(), 0.0), _pressure, E, std::move(L)});
}

void MonolithicConduits::set_time_derivative(System& system, const TimeDerivative& d)
{
  const bool changed = d.coefficients() != _derivative.coefficients();
  _derivative = d;
  if (changed)
    append(system);
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
  _time = t;
  AppendedUnknowns& appended = system.appended();
  _faults->load(step(t), _pressure_old, _pressure, appended.b);
  // The open cells' volume at u^i, which B's rows move to u^{i+1}, and
  // Newton's term at u^i: G (J u^i - (w_h - w_c)), the transmissibilities'
  // change from the conducting apertures w_c to w_h(u^{i+1}).
  la::petsc::Vector X = wrap(x);
  check_conduits(MatMult(_J, X.vec(), _cells), "MatMult by J");
  Vec newton = nullptr;
  check_conduits(VecDuplicate(_cells, &newton), "VecDuplicate");
  const std::vector<double> rates = _faults->opening_rates(step(t), _pressure_old, _pressure);
  const std::vector<double> lag = _faults->conducting_lag();
  double* Ju = nullptr;
  check_conduits(VecGetArray(_cells, &Ju), "VecGetArray");
  for (std::size_t k = 0; k < rates.size(); ++k)
    appended.b[k] += rates[k] * Ju[k], Ju[k] -= lag[k];
  check_conduits(VecRestoreArray(_cells, &Ju), "VecRestoreArray");
  check_conduits(MatMult(_G, _cells, newton), "MatMult by G");
  const double* n = nullptr;
  check_conduits(VecGetArrayRead(newton, &n), "VecGetArrayRead");
  for (std::size_t k = 0; k < rates.size(); ++k)
    appended.b[k] += n[k];
  check_conduits(VecRestoreArrayRead(newton, &n), "VecRestoreArrayRead");
  check_conduits(VecDestroy(&newton), "VecDestroy");
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
  // A NaN would drop out of std::max (and make MPI's maximum differ
  // between ranks): the change is infinite then, on every rank.
  if (!std::all_of(_pressure.begin(), _pressure.end(), [](double v) { return std::isfinite(v); }))
    moved[0] = std::numeric_limits<double>::infinity();
  MPI_Allreduce(MPI_IN_PLACE, moved.data(), 2, MPI_DOUBLE, MPI_MAX, _problem.domain.mesh->comm());
  const double tolerance = _problem.scene.coupling->tolerance;
  _change = {_faults->aperture_change(), moved[1] > 0 ? moved[0] / moved[1] : moved[0]};
  const bool converged
      = _change[0] <= tolerance and std::isfinite(moved[0]) and moved[0] <= tolerance * moved[1];
  if (!converged) // the next iterate's rows: its apertures, and B's Newton term at its p_f
    append(system);
  return converged;
}

void MonolithicConduits::drop_newton(System& system)
{
  _faults->drop_newton();
  append(system);
}

std::string MonolithicConduits::last_change() const
{
  std::ostringstream s;
  s << "the last iteration moved the apertures by " << _change[0] << " relative ("
    << (std::isinf(_change[0]) ? "a cell opened or closed" : "no cell opened or closed") << ") and p_f by "
    << _change[1] << " relative, against coupling.tolerance = " << _problem.scene.coupling->tolerance;
  return s.str();
}

std::vector<double> MonolithicConduits::normal_stress(const ContactState& state) const
{
  return _aperture->cell_means(pair_tractions(state));
}

void MonolithicConduits::accept(std::span<const double> x, double t)
{
  _faults->add_volumes(_faults->step_volumes(x, _pressure, _pressure_old, step(t)), step(t), _pressure_old);
  _faults->set_intersection_rates(_pressure);
}

std::string MonolithicConduits::unbalanced(std::span<const double> x, double t, double rock_flux) const
{
  return _faults->unbalanced(_faults->step_volumes(x, _pressure, _pressure_old, step(t)), rock_flux);
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
