#include "contact/contact.h"

#include "assembly/linear_algebra.h"

#include <algorithm>
#include <cmath>
#include <dolfinx/fem/DirichletBC.h>
#include <dolfinx/fem/FunctionSpace.h>
#include <dolfinx/fem/utils.h>
#include <optional>
#include <utility>

namespace biotcontact
{
using namespace dolfinx;

ContactSolver::ContactSolver(MPI_Comm comm, const SystemLayout& system, Method method, ContactOperators operators,
                             ContactUnknowns unknowns)
    : _comm(comm), _A(operators.A), _P(operators.P), _fields(system.fields), _structure(system.structure),
      _prefix(system.prefix), _set(std::move(unknowns.set)), _displacement_dofs(std::move(unknowns.displacement_dofs))
{
  const std::string& prefix = system.prefix;
  const Vec layout = unknowns.layout;
  for (std::int32_t dof : _set.dofs)
    _dofs.push_back(_displacement_dofs.at(dof));
  _set.bonded.assign(_set.dofs.size(), 1);
  _bonded_accepted = _set.bonded;
  // MAT_SPD carries over to the inactive-set submatrices: Cholesky there.
  if (_structure == Structure::spd)
    check_petsc(MatSetOption(_A, MAT_SPD, PETSC_TRUE), "contact solver: MatSetOption MAT_SPD of A");
  check_petsc(VecDuplicate(layout, &_force), "contact solver: VecDuplicate of the layout");
  check_petsc(VecDuplicate(layout, &_x_start), "contact solver: VecDuplicate of the layout");
  check_petsc(VecDuplicate(layout, &_x_start_vi), "contact solver: VecDuplicate of the layout");
  check_petsc(VecSet(_x_start, 0.0), "contact solver: VecSet of the step's start");
  make_change_of_variables(layout);

  long local_dofs = static_cast<long>(contact_dofs().size()), all_dofs = 0;
  MPI_Allreduce(&local_dofs, &all_dofs, 1, MPI_LONG, MPI_SUM, comm);
  const PathCosts costs{method, static_cast<PetscInt>(all_dofs), operators.changing, operators.once};
  const ContactPathChoice choice = choose_contact_path(comm, prefix, costs);
  const ContactPath path = choice.path;
  _condensed_on_failure = choice.condensed_on_failure;
  if (path == ContactPath::condensed)
    _vi = condensed_vi();
  else
  {
    VIProblem problem = pose_on_full_system(layout, std::move(unknowns.separate_rows));
    problem.changing = operators.changing;
    add_friction(problem);
    _full_steps = problem.frictional ? 2 : 1; // stick and slip settle in a second step (docs/schemes.md, "Faults")
    _vi = std::make_unique<VariationalInequality>(std::move(problem),
                                                  WholeSystem{comm, _A_vi, _P_vi, {prefix, _structure, _fields}, method});
    _then_condensed = path == ContactPath::full_then_condensed;
  }
}

std::unique_ptr<VariationalInequality> ContactSolver::condensed_vi()
{
  VIProblem problem = condense();
  Vec y = problem.layout; // the VI keeps a duplicate
  add_friction(problem);
  auto vi = std::make_unique<VariationalInequality>(std::move(problem), std::nullopt);
  check_petsc(VecDestroy(&y), "contact solver: VecDestroy of the condensed layout");
  return vi;
}

std::unique_ptr<VariationalInequality> ContactSolver::switch_to_condensed(std::string after)
{
  std::unique_ptr<VariationalInequality> vi = condensed_vi();
  vi->continue_from(*_vi);
  std::swap(_vi, vi);
  _then_condensed = _condensed_on_failure = false;
  _after = std::move(after);
  // Friction's slip increments are measured from the step's start.
  if (Vec reference = _vi->slip_reference())
    _schur->restrict_to_contact(to_vi(_x_start, _x_start_vi), reference);
  return vi;
}

void ContactSolver::back_to_full(std::unique_ptr<VariationalInequality> full)
{
  full->continue_from(*_vi);
  _vi = std::move(full);
  _schur.reset();
  _schur_current = false;
  _condensed_on_failure = true;
  _after.clear();
}

/// The VI on the Schur complement H = C A^-1 C^T of the contact DOFs
/// (schur_complement.h): every unknown of the small dense problem is bounded.
VIProblem ContactSolver::condense()
{
  const std::vector<std::int32_t> dofs = contact_dofs();
  _schur = std::make_unique<SchurComplement>(_comm, _prefix, _A_vi, _structure, dofs);
  const PetscInt m = _schur->size();
  // Every rank solves the same small problem.
  VIProblem p{PETSC_COMM_SELF, _prefix + "contact_", _prefix + "contact", _prefix, _schur->matrix(), nullptr};
  p.shared = _comm;
  check_petsc(VecCreateSeq(PETSC_COMM_SELF, m, &p.layout), "contact solver: VecCreateSeq of the condensed layout");
  // Each rank's constraints come first among its contact DOFs, its
  // tangential ones (friction) after them: the bounded DOFs of H are the
  // constraints'.
  std::vector<double> bounded(dofs.size(), 0.0), gap(dofs.size(), 0.0), sign(dofs.size(), 0.0);
  for (std::size_t k = 0; k < _dofs.size(); ++k)
    bounded[k] = 1, gap[k] = _set.gap[k], sign[k] = _set.sign[k];
  std::vector<double> all_bounded(m), all_gap(m), all_sign(m);
  _schur->gather(bounded.data(), all_bounded.data());
  _schur->gather(gap.data(), all_gap.data());
  _schur->gather(sign.data(), all_sign.data());
  for (PetscInt k = 0; k < m; ++k)
    if (all_bounded[k] > 0)
    {
      p.bounded.push_back(static_cast<std::int32_t>(k));
      p.gap.push_back(all_gap[k]);
      p.sign.push_back(all_sign[k]);
    }
  // H is small and dense: LAPACK's factorisation, Cholesky when A is SPD
  // but for the Jacobian of friction, which is not symmetric.
  set_default_option(p.prefix + "ksp_type", "preonly");
  const bool symmetric = _structure == Structure::spd and !any_frictional(_set, _comm);
  set_default_option(p.prefix + "pc_type", symmetric ? "cholesky" : "lu");
  set_default_option(p.prefix + "pc_factor_mat_solver_type", "petsc");
  return p;
}

std::vector<std::int32_t> ContactSolver::contact_dofs() const
{
  std::vector<std::int32_t> dofs = _dofs;
  for (std::size_t k = 0; k < _dofs.size(); ++k)
    if (_set.frictional[k])
      for (int r = 1; r < _set.dim; ++r)
        dofs.push_back(_displacement_dofs.at(_set.dofs[k] + r));
  return dofs;
}

/// The frictional constraints in the VI's numbering: on the full system
/// this rank's, at their local positions; condensed, every rank's at their
/// places in H (each rank's contact DOFs from offset(), contact_dofs()'s
/// order), gathered to every rank.
void ContactSolver::add_friction(VIProblem& problem) const
{
  problem.friction = frictional_constraints();
  problem.tangents = _set.dim - 1;
  problem.frictional = any_frictional(_set, _comm);
}

std::vector<FrictionalConstraint> ContactSolver::frictional_constraints() const
{
  const int d = _set.dim;
  const PetscInt first = _schur ? _schur->offset() : 0;
  std::vector<FrictionalConstraint> mine;
  PetscInt next = static_cast<PetscInt>(_dofs.size());
  for (std::size_t k = 0; k < _dofs.size(); ++k)
  {
    if (!_set.frictional[k])
      continue;
    FrictionalConstraint f;
    f.normal = _schur ? first + static_cast<PetscInt>(k) : _dofs[k];
    for (int r = 1; r < d; ++r, ++next)
      f.tangential[r - 1] = _schur ? first + next : _displacement_dofs[_set.dofs[k] + r];
    f.sign = _set.sign[k], f.gap = _set.gap[k], f.lumped = _set.lumped[k];
    f.law = constraint_law(_set, k);
    mine.push_back(f);
  }
  return _schur ? all_gather_constraints(mine, _comm) : mine;
}

bool ContactSolver::break_pulled_bonds()
{
  // Decided alike on every rank (update_bonds is collective): a rank
  // without frictional constraints of its own has no flags (the full
  // path) but still takes part.
  if (!_vi->frictional())
    return false;
  const std::vector<char>& closed = _vi->closed_when_clamped();
  // The VI's constraints: this rank's, or condensed every rank's in rank order.
  long mine = std::count(_set.frictional.begin(), _set.frictional.end(), 1), first = 0;
  if (_schur)
    MPI_Exscan(&mine, &first, 1, MPI_LONG, MPI_SUM, _comm);
  int rank = 0;
  MPI_Comm_rank(_comm, &rank);
  return update_bonds(biotcontact::break_pulled_bonds(_set, closed, rank == 0 ? 0 : first));
}

bool ContactSolver::update_bonds(bool changed)
{
  int any = changed;
  MPI_Allreduce(MPI_IN_PLACE, &any, 1, MPI_INT, MPI_LOR, _comm);
  if (any)
    _vi->set_friction(frictional_constraints());
  return any;
}

void ContactSolver::accept_step(Vec x)
{
  const bool broke = break_open_bonds(_set, active_set(x).flags);
  _bonded_accepted = _set.bonded;
  update_bonds(broke);
}

void ContactSolver::restore_bonds(const std::vector<double>& broken)
{
  _bonded_accepted = bonds_from_names(_set, broken);
  _set.bonded = _bonded_accepted;
  update_bonds(true);
}

/// The VI on the full system: only the contact DOFs are bounded.
VIProblem ContactSolver::pose_on_full_system(Vec layout, std::vector<std::int32_t> separate_rows) const
{
  VIProblem p{_comm, _prefix, "", _prefix, _A_vi, layout, _dofs, _set.gap, {}};
  p.sign.assign(_set.sign.begin(), _set.sign.end());
  p.separate_rows = std::move(separate_rows);
  return p;
}

std::string ContactSolver::method() const
{
  if (!_schur)
    return "full";
  return "condensed on " + std::to_string(_schur->size()) + " contact DOFs" + (_after.empty() ? "" : ", " + _after);
}

void ContactSolver::set_tolerance(double relative) { _vi->set_tolerance(relative); }

void ContactSolver::operator_changed()
{
  // H and A' are formed again at the next solve.
  _schur_current = false;
  _change_current = false;
  _solved.forget();
  _vi->operator_changed();
}

ContactSolver::~ContactSolver()
{
  for (Vec* v : {&_force, &_x_vi, &_b_vi, &_x_start, &_x_start_vi})
    warn_petsc(VecDestroy(v), "contact solver: VecDestroy");
  if (_change)
  {
    if (_P_vi != _A_vi)
      warn_petsc(MatDestroy(&_P_vi), "contact solver: MatDestroy of P'");
    warn_petsc(MatDestroy(&_A_vi), "contact solver: MatDestroy of A'");
  }
}

void ContactSolver::solve(Vec b, Vec x)
{
  change_operators();
  Vec b_vi = b;
  if (_change)
  {
    _change->dual(b, _b_vi);
    b_vi = _b_vi;
  }
  Vec x_vi = to_vi(x, _x_vi);
  if (!_then_condensed or !solve_vi(b_vi, x_vi, _full_steps))
  {
    if (_then_condensed)
      switch_to_condensed(_full_steps == 1 ? "after one full Newton step" : "after two full Newton steps");
    // A solve that fails on every path is solved again from its start
    // (x_vi) when it broke a bond: the pairs that its clamped start (every
    // pair closed and stuck) pulls slip on friction alone (contact_law.h).
    // Bonds break only where no solution keeps them.
    for (int rounds = 0;; ++rounds)
      try
      {
        solve_on_path(b_vi, x_vi);
        break;
      }
      catch (const SolverError& e)
      {
        // With friction, a change of load that changes too many states for
        // one Newton solve: through the loads between (load_continuation.h).
        if (rounds == 0 and _solved.known()
            and continue_load(_solved, b_vi, x_vi, [this](Vec b, Vec y) { solve_on_path(b, y); },
                             continuation_solves))
          break;
        if (break_pulled_bonds())
          continue;
        if (rounds == 0)
          throw;
        throw BondFailure(std::string(e.what()) + " (also after breaking the bonds its clamped start pulled, "
                          + std::to_string(rounds) + (rounds == 1 ? " time)" : " times)"));
      }
  }
  if (_vi->frictional())
    _solved.keep(b_vi, x_vi);
  if (_change)
    _change->backward(x_vi, x);
}

void ContactSolver::solve_on_path(Vec b_vi, Vec x_vi)
{
  if (!_condensed_on_failure)
  {
    solve_vi(b_vi, x_vi, 0);
    return;
  }
  // The condensed VI is the same problem with the other unknowns solved
  // exactly at every Newton step, so its line search judges the contact
  // rows alone: it settles contact states between which the whole
  // system's semismooth Newton steps cycle (docs/theory.md, "Friction").
  // x_vi is still the start: a failed solve leaves it as it was.
  try
  {
    solve_vi(b_vi, x_vi, 0);
  }
  catch (const SolverError&)
  {
    std::unique_ptr<VariationalInequality> full = switch_to_condensed("after a full solve that did not converge");
    try
    {
      solve_vi(b_vi, x_vi, 0);
    }
    catch (const SolverError&)
    {
      back_to_full(std::move(full)); // condensing did not mend it either: a broken bond may (solve)
      throw;
    }
  }
}

bool ContactSolver::solve_vi(Vec b_vi, Vec x_vi, int newton_steps)
{
  if (_schur and !_schur_current)
  {
    _schur->assemble();
    _schur_current = true;
  }
  // The VI's load and start: on C alone when condensed, (H, g) with y = x_C
  // (schur_complement.h).
  if (_schur)
  {
    _schur->condensed_load(b_vi, _vi->load());
    _schur->restrict_to_contact(x_vi, _vi->unknown());
  }
  else
  {
    check_petsc(VecCopy(b_vi, _vi->load()), "contact solver: VecCopy of the load");
    check_petsc(VecCopy(x_vi, _vi->unknown()), "contact solver: VecCopy of the VI's start");
  }
  _vi->pin(_pinned ? pins_in_vi() : std::vector<std::int8_t>{});
  // In units of the displacement scale (the largest gap or |x|).
  const double scale = displacement_scale(_set, _displacement_dofs, x_vi, _comm);
  if (newton_steps == 0)
    _vi->solve(scale);
  else if (!_vi->try_solve(scale, newton_steps))
    return false;
  if (_schur)
    _schur->extend(b_vi, _vi->unknown(), x_vi);
  else
    check_petsc(VecCopy(_vi->unknown(), x_vi), "contact solver: VecCopy of the solution");
  return true;
}

void ContactSolver::set_slip_reference(Vec x)
{
  check_petsc(VecCopy(x, _x_start), "contact solver: VecCopy of the step's start");
  // A step tried again starts from the bonds of the last accepted one.
  const bool changed = _set.bonded != _bonded_accepted;
  _set.bonded = _bonded_accepted;
  update_bonds(changed);
  Vec reference = _vi->slip_reference();
  if (!reference)
    return;
  Vec x_vi = to_vi(x, _x_vi);
  if (_schur)
    _schur->restrict_to_contact(x_vi, reference);
  else
    check_petsc(VecCopy(x_vi, reference), "contact solver: VecCopy of the slip reference");
}

void ContactSolver::make_change_of_variables(Vec layout)
{
  _A_vi = _A;
  _P_vi = _P;
  long local = static_cast<long>(_set.blocks.size()), global = 0;
  MPI_Allreduce(&local, &global, 1, MPI_LONG, MPI_SUM, _comm);
  if (global == 0)
    return;
  std::vector<std::int64_t> requested;
  for (const ContactBlock& block : _set.blocks)
    requested.insert(requested.end(), block.dofs.begin(), block.dofs.end());
  PetscInt start = 0;
  check_petsc(VecGetOwnershipRange(layout, &start, nullptr), "contact solver: VecGetOwnershipRange of the layout");
  const std::vector<PetscInt> positions
      = solved_positions(requested, start, _displacement_dofs, _set.dof_offset, _comm);
  std::vector<ChangeOfVariables::Block> blocks;
  std::size_t next = 0;
  for (const ContactBlock& block : _set.blocks)
  {
    ChangeOfVariables::Block b{{}, block.T};
    for (std::size_t i = 0; i < block.dofs.size(); ++i)
      b.dofs.push_back(positions[next++]);
    blocks.push_back(std::move(b));
  }
  _change = std::make_unique<ChangeOfVariables>(_A, blocks, _structure == Structure::spd);
  _A_vi = nullptr;
  _change->congruence(_A, &_A_vi);
  if (_P != _A)
  {
    _P_vi = nullptr;
    _change->congruence(_P, &_P_vi);
  }
  else
    _P_vi = _A_vi;
  _change_current = true;
  check_petsc(VecDuplicate(layout, &_x_vi), "contact solver: VecDuplicate of the layout");
  check_petsc(VecDuplicate(layout, &_b_vi), "contact solver: VecDuplicate of the layout");
  // The rigid-body modes of a field (the displacement of the coupled
  // system) change with its DOFs.
  for (Field& f : _fields)
    if (f.near_nullspace)
      f.near_nullspace = own(_change->transformed(f.near_nullspace.get(), &f.dofs, layout));
}

void ContactSolver::change_operators()
{
  if (!_change or _change_current)
    return;
  _change->congruence(_A, &_A_vi);
  if (_P_vi != _A_vi)
    _change->congruence(_P, &_P_vi);
  _change_current = true;
}

Vec ContactSolver::to_vi(Vec x, Vec work) const
{
  if (!_change)
    return x;
  _change->forward(x, work);
  return work;
}

std::vector<double> ContactSolver::distances(Vec x) const
{
  const PetscScalar* X;
  Vec x_vi = to_vi(x, _x_vi);
  check_petsc(VecGetArrayRead(x_vi, &X), "contact solver: VecGetArrayRead of x");
  std::vector<double> distance(_dofs.size());
  for (std::size_t k = 0; k < _dofs.size(); ++k)
    distance[k] = _set.gap[k] - _set.sign[k] * X[_dofs[k]];
  check_petsc(VecRestoreArrayRead(x_vi, &X), "contact solver: VecRestoreArrayRead of x");
  return distance;
}

Vec ContactSolver::contact_force(Vec x, Vec b)
{
  check_petsc(MatMult(_A, x, _force), "contact solver: MatMult of A for the contact force");
  check_petsc(VecAXPY(_force, -1.0, b), "contact solver: VecAXPY of the contact force");
  if (!_change)
    return _force;
  _change->dual(_force, _b_vi);
  return _b_vi;
}

ActiveSet ContactSolver::active_set(Vec x) const
{
  const double scale = displacement_scale(_set, _displacement_dofs, x, _comm);
  ActiveSet set;
  for (double distance : distances(x))
    set.flags.push_back(on_foundation(distance, scale));
  int local = static_cast<int>(std::count(set.flags.begin(), set.flags.end(), 1));
  MPI_Allreduce(&local, &set.nodes, 1, MPI_INT, MPI_SUM, _comm);
  return set;
}

ContactState ContactSolver::state(Vec x, Vec b, fem::Function<double>& pressure_out,
                                  fem::Function<double>& active_out)
{
  const std::vector<double> distance = distances(x);
  // Nodal contact force R = A x - b (the residual of the unconstrained
  // equations), in the new variables R' = T^{-T} R: the multiplier of each
  // constraint.
  Vec force = contact_force(x, b);
  Vec x_vi = to_vi(x, _x_vi), start_vi = to_vi(_x_start, _x_start_vi);
  const PetscScalar *X, *start, *R;
  check_petsc(VecGetArrayRead(x_vi, &X), "contact solver: VecGetArrayRead of x");
  check_petsc(VecGetArrayRead(start_vi, &start), "contact solver: VecGetArrayRead of the step's start");
  check_petsc(VecGetArrayRead(force, &R), "contact solver: VecGetArrayRead of the contact force");
  const std::vector<double> pressure = contact_pressures(_set, _dofs, R);
  const auto jump = junction_jumps(_set, _displacement_dofs, x, _comm);
  const auto jump_start = junction_jumps(_set, _displacement_dofs, _x_start, _comm);
  const ContactMeasurement measured{_set, _displacement_dofs, distance, pressure, displacement_scale(_set, _displacement_dofs, x, _comm),
                                    X, start, R, jump, jump_start};
  ContactState s = contact_state(measured, {pressure_out, active_out}, _comm);
  check_petsc(VecRestoreArrayRead(x_vi, &X), "contact solver: VecRestoreArrayRead of x");
  check_petsc(VecRestoreArrayRead(start_vi, &start), "contact solver: VecRestoreArrayRead of the step's start");
  check_petsc(VecRestoreArrayRead(force, &R), "contact solver: VecRestoreArrayRead of the contact force");
  return s;
}

} // namespace biotcontact
