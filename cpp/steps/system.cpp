#include "steps/system.h"

#include "solvers/block_matrix.h"

#include <algorithm>
#include <array>
#include <stdexcept>
#include <dolfinx/common/Timer.h>

namespace biotcontact
{
using namespace dolfinx;

namespace
{
la::petsc::Matrix timed_assembly(const fem::Form<double>& a, const BCs& bcs, double& time)
{
  common::Timer timer("assembly");
  la::petsc::Matrix A = assemble_matrix(a, bcs);
  time += timer.stop();
  return A;
}

/// check_petsc with "<the system> system: <call>", the text built only when
/// the call failed (MatSetValue runs once per appended diagonal entry).
void check_system(PetscErrorCode code, const std::string& prefix, const char* call)
{
  if (code != 0)
    check_petsc(code, system_name(prefix) + " system: " + call);
}
} // namespace

System::System(MPI_Comm comm, std::shared_ptr<const fem::Form<double>> a, BCs bcs, const SystemLayout& layout,
               SolverChoice choice, std::shared_ptr<const fem::Form<double>> a_preconditioner)
    : _comm(comm), _prefix(layout.prefix), _a(a), _bcs(std::move(bcs)), _structure(layout.structure),
      _fields(layout.fields), _A(timed_assembly(*a, _bcs, _statistics.assembly_time)),
      _stage(_prefix.substr(0, _prefix.size() - 1))
{
  int ranks = 1;
  MPI_Comm_size(comm, &ranks);
  const MethodChoice chosen = set_solver_defaults(
      _prefix, _structure,
      choose_method(choice, _structure, unknowns(), a->mesh()->topology().dim(), ranks, is_coupled(_fields)), _comm,
      _fields);
  _method = chosen.method;
  _method_reason = chosen.reason;
  // A factorisation is of A itself; only a preconditioner takes another matrix.
  if (a_preconditioner and _method == Method::iterative)
  {
    _a_preconditioner = a_preconditioner;
    _P.emplace(timed_assembly(*a_preconditioner, _bcs, _statistics.assembly_time));
  }
  // Made now so that options that make no solver are refused before the run.
  _linear = std::make_unique<LinearSolver>(_comm, _prefix, _A.mat(), preconditioner_matrix(), _structure, _fields);
}

std::int64_t System::unknowns() const
{
  PetscInt n = 0;
  check_system(MatGetSize(_A.mat(), &n, nullptr), _prefix, "MatGetSize");
  return n;
}

void System::set_near_nullspace(MatNullSpace modes)
{
  // The modes are the displacement's; the ties hold flux DOFs only.
  check_system(MatSetNearNullSpace(_A.mat(), modes), _prefix, "MatSetNearNullSpace");
  if (_A_tied)
    check_system(MatSetNearNullSpace(_A_tied, modes), _prefix, "MatSetNearNullSpace of the tied matrix");
}

System::~System()
{
  _contact.reset();
  _linear.reset();
  for (Mat* m : {&_A_tied, &_P_tied, &_A_appended, &_P_appended, &_appended.B, &_appended.C, &_appended.E})
    warn_petsc(MatDestroy(m), "a system: MatDestroy");
  for (Vec* v : {&_b_appended, &_x_appended, &_b_tied, &_y_tied})
    warn_petsc(VecDestroy(v), "a system: VecDestroy");
}

void System::tie(const std::vector<Tie>& ties)
{
  long local = static_cast<long>(ties.size()), global = 0;
  MPI_Allreduce(&local, &global, 1, MPI_LONG, MPI_SUM, _comm);
  if (global == 0) // a scene without transparent faults builds nothing
    return;
  _tied = std::make_unique<TiedDofs>(_A.mat(), ties);
  _tied->reduce(_A.mat(), &_A_tied);
  if (_P)
    _tied->reduce(_P->mat(), &_P_tied);
  MatNullSpace modes = nullptr;
  check_system(MatGetNearNullSpace(_A.mat(), &modes), _prefix, "MatGetNearNullSpace");
  if (modes)
    check_system(MatSetNearNullSpace(_A_tied, modes), _prefix, "MatSetNearNullSpace of the tied matrix");
  check_system(MatCreateVecs(_A_tied, &_y_tied, &_b_tied), _prefix, "MatCreateVecs of the tied matrix");
  _linear = std::make_unique<LinearSolver>(_comm, _prefix, operator_matrix(), preconditioner_matrix(), _structure,
                                           _fields);
}

Mat System::appended_operator(Mat a, const std::vector<double>* diagonal, Mat into, FilledFrom& filled)
{
  // a's block changes with a only (reassembled: a new dt, a restart), B, E
  // and C with the apertures at every iteration: a's rows, most of the
  // whole matrix, are set again only when a was reassembled (0.21 of the
  // 0.34 s the 50-fracture network's 61 refills took at 97,275 unknowns).
  // D on any rank: A + D is made on every rank (the calls are
  // collective), also where a rank owns no row of D.
  int any_diagonal = !_appended.diagonal.empty();
  MPI_Allreduce(MPI_IN_PLACE, &any_diagonal, 1, MPI_INT, MPI_LOR, _comm);
  const bool a_kept = into and !any_diagonal and filled.a == a and filled.version == _version;
  filled = any_diagonal ? FilledFrom{} : FilledFrom{a, _version};
  if (any_diagonal)
  {
    check_system(MatDuplicate(a, MAT_COPY_VALUES, &a), _prefix, "MatDuplicate of A");
    for (const auto& [row, value] : _appended.diagonal)
      check_system(MatSetValue(a, row, row, value, ADD_VALUES), _prefix, "MatSetValue of the appended diagonal");
    check_system(MatAssemblyBegin(a, MAT_FINAL_ASSEMBLY), _prefix, "MatAssemblyBegin of A + D");
    check_system(MatAssemblyEnd(a, MAT_FINAL_ASSEMBLY), _prefix, "MatAssemblyEnd of A + D");
  }
  Mat C = _appended.C;
  if (diagonal) // on every rank: the calls are collective
  {
    Vec c = nullptr;
    check_system(MatDuplicate(_appended.C, MAT_COPY_VALUES, &C), _prefix, "MatDuplicate of C");
    check_system(MatCreateVecs(C, nullptr, &c), _prefix, "MatCreateVecs of C");
    double* entries = nullptr;
    check_system(VecGetArray(c, &entries), _prefix, "VecGetArray of C's diagonal");
    std::copy(diagonal->begin(), diagonal->end(), entries);
    check_system(VecRestoreArray(c, &entries), _prefix, "VecRestoreArray of C's diagonal");
    check_system(MatDiagonalSet(C, c, ADD_VALUES), _prefix, "MatDiagonalSet of C");
    check_system(VecDestroy(&c), _prefix, "VecDestroy of C's diagonal");
  }
  Mat E = _appended.E;
  if (!E)
    check_system(MatTranspose(_appended.B, MAT_INITIAL_MATRIX, &E), _prefix, "MatTranspose of B");
  // The first time a conversion of the blocks' nest; then the same
  // structure's values, row by row (the conversion cost 18 ms a call on 2
  // ranks against 3 on 1: docs/performance.md, thirty-fifth session).
  const std::array<Mat, 4> blocks{a, E, _appended.B, C};
  const BlockMatrix layout(a, C);
  Mat big = into;
  if (into)
    layout.refill(into, {a_kept ? nullptr : a, E, _appended.B, C});
  else
    big = layout.convert(_comm, blocks);
  if (!_appended.E)
    check_system(MatDestroy(&E), _prefix, "MatDestroy of B^T");
  if (any_diagonal)
    check_system(MatDestroy(&a), _prefix, "MatDestroy of A + D");
  if (C != _appended.C)
    check_system(MatDestroy(&C), _prefix, "MatDestroy of C + c");
  return big;
}

void System::append(AppendedUnknowns appended)
{
  const bool first = _A_appended == nullptr;
  for (Mat* m : {&_appended.B, &_appended.C, &_appended.E})
    check_system(MatDestroy(m), _prefix, "MatDestroy of the appended blocks");
  _appended = std::move(appended);
  Mat big = appended_operator(_A_tied ? _A_tied : _A.mat(), nullptr, _A_appended, _A_filled);
  // The fixed-stress preconditioner's matrix gets the same rows, its own
  // fixed-stress term on C's diagonal.
  Mat big_P = _P ? appended_operator(_P_tied ? _P_tied : _P->mat(), &_appended.preconditioner_diagonal, _P_appended,
                                     _P_filled)
                 : nullptr;
  if (!first)
  {
    if (_contact)
      _contact->operator_nudged();
    else
      _linear->operator_nudged();
    return;
  }
  _A_appended = big;
  _P_appended = big_P;
  check_system(MatCreateVecs(big, &_x_appended, &_b_appended), _prefix, "MatCreateVecs of the appended system");
  PetscInt rows = 0;
  check_system(MatGetLocalSize(_appended.C, &rows, nullptr), _prefix, "MatGetLocalSize of C");
  append_to_fields(rows);
  if (_contact)
    throw std::runtime_error(_prefix + ": unknowns appended after the contact (append before use_contact)");
  _linear = std::make_unique<LinearSolver>(_comm, _prefix, _A_appended, preconditioner_matrix(), _structure, _fields);
}

void System::append_to_fields(PetscInt rows)
{
  // The nest's conversion numbers rank by rank, A's rows then C's: a rank's
  // rows move by the rows appended on the ranks before it, in the whole
  // system's numbering and in a block's (the coupled system's "flow").
  PetscInt shift = 0, first = 0, local = 0;
  MPI_Exscan(&rows, &shift, 1, MPIU_INT, MPI_SUM, _comm);
  int rank = 0;
  MPI_Comm_rank(_comm, &rank);
  shift = rank == 0 ? 0 : shift; // MPI_Exscan leaves rank 0's undefined
  check_system(MatGetOwnershipRange(_A.mat(), &first, nullptr), _prefix, "MatGetOwnershipRange");
  check_system(MatGetLocalSize(_A.mat(), &local, nullptr), _prefix, "MatGetLocalSize");
  const PetscInt start = first + shift + local; // this rank's first appended row
  auto add = [rows](std::vector<PetscInt>& dofs, PetscInt first)
  {
    for (PetscInt r = 0; r < rows; ++r)
      dofs.push_back(first + r);
  };
  auto move = [shift](std::vector<PetscInt>& dofs)
  {
    for (PetscInt& dof : dofs)
      dof += shift;
  };
  for (Field& f : _fields)
  {
    const PetscInt block_start = block_offset(f, _comm) + shift + static_cast<PetscInt>(f.dofs.size());
    move(f.dofs);
    if (f.name == "pressure")
      add(f.dofs, start);
    if (f.name != "flow") // the coupled system's, whose splits number its block
      continue;
    add(f.dofs, start);
    for (Field& g : f.fields)
    {
      move(g.dofs);
      if (g.name == "pressure")
        add(g.dofs, block_start);
    }
  }
}

void System::copy_in(Vec x, const std::vector<double>& appended, Vec whole)
{
  PetscInt n = 0;
  check_petsc(VecGetLocalSize(x, &n), "the appended unknowns: VecGetLocalSize");
  const double* from = nullptr;
  double* to = nullptr;
  check_petsc(VecGetArrayRead(x, &from), "the appended unknowns: VecGetArrayRead");
  check_petsc(VecGetArray(whole, &to), "the appended unknowns: VecGetArray");
  std::copy_n(from, n, to);
  std::copy(appended.begin(), appended.end(), to + n);
  check_petsc(VecRestoreArray(whole, &to), "the appended unknowns: VecRestoreArray");
  check_petsc(VecRestoreArrayRead(x, &from), "the appended unknowns: VecRestoreArrayRead");
}

std::pair<Vec, Vec> System::whole(Vec x, Vec b)
{
  if (!_A_appended)
    return {x, b};
  copy_in(x, _appended.x, _x_appended);
  copy_in(b, _appended.b, _b_appended);
  return {_x_appended, _b_appended};
}

void System::solve_appended(Vec b, Vec x)
{
  PetscInt n = 0;
  check_system(VecGetLocalSize(b, &n), _prefix, "VecGetLocalSize");
  copy_in(b, _appended.b, _b_appended);
  copy_in(x, _appended.x, _x_appended);
  if (_contact)
    _contact->solve(_b_appended, _x_appended);
  else
    _statistics.linear_iterations += _linear->solve(_x_appended, _b_appended);
  const double* from = nullptr;
  double* to = nullptr;
  check_system(VecGetArrayRead(_x_appended, &from), _prefix, "VecGetArrayRead of [x; y]");
  check_system(VecGetArray(x, &to), _prefix, "VecGetArray of x");
  std::copy_n(from, n, to);
  std::copy(from + n, from + n + _appended.x.size(), _appended.x.begin());
  check_system(VecRestoreArray(x, &to), _prefix, "VecRestoreArray of x");
  check_system(VecRestoreArrayRead(_x_appended, &from), _prefix, "VecRestoreArrayRead of [x; y]");
}

void System::use_contact(ContactSet set, std::vector<std::int32_t> displacement_dofs, Vec layout,
                         std::vector<std::int32_t> balance_rows, bool once)
{
  _linear.reset();
  if (_A_appended)
  {
    PetscInt rows = 0, appended = 0;
    check_system(MatGetLocalSize(_A.mat(), &rows, nullptr), _prefix, "MatGetLocalSize");
    check_system(MatGetLocalSize(_appended.C, &appended, nullptr), _prefix, "MatGetLocalSize of C");
    for (PetscInt r = 0; r < appended; ++r)
      balance_rows.push_back(static_cast<std::int32_t>(rows + r));
  }
  _contact = std::make_unique<ContactSolver>(
      _comm, SystemLayout{_prefix, _structure, _fields}, _method,
      ContactOperators{operator_matrix(), preconditioner_matrix(), _A_appended != nullptr, once},
      ContactUnknowns{std::move(set), std::move(displacement_dofs), _x_appended ? _x_appended : layout,
                      std::move(balance_rows)});
}

void System::begin_step(Vec x)
{
  if (_contact and _A_appended)
    copy_in(x, _appended.x, _x_appended);
  if (_contact)
    _contact->set_slip_reference(_A_appended ? _x_appended : x);
}

void System::accept_step(Vec x)
{
  if (_contact and _A_appended)
    copy_in(x, _appended.x, _x_appended);
  if (_contact)
    _contact->accept_step(_A_appended ? _x_appended : x);
}

void System::solve(Vec b, Vec x)
{
  SolverStage::Guard stage(_stage);
  common::Timer timer("solve " + _prefix);
  if (_tied) // solve for y, x = P y (tied_dofs.h)
  {
    _tied->load(b, _b_tied);
    _tied->guess(x, _y_tied);
    b = _b_tied;
  }
  Vec y = _tied ? _y_tied : x;
  if (_A_appended)
    solve_appended(b, y);
  else if (_contact)
    _contact->solve(b, y);
  else
    _statistics.linear_iterations += _linear->solve(y, b);
  if (_tied)
    _tied->expand(_y_tied, x);
  _statistics.total_time += timer.stop();
  ++_statistics.solves;
}

void System::set_tolerance(double relative)
{
  if (_method != Method::iterative)
    return;
  if (_contact)
    _contact->set_tolerance(relative);
  else
    _linear->set_tolerance(relative);
}

void System::reassemble()
{
  common::Timer timer("assembly");
  reassemble_matrix(_A.mat(), *_a, _bcs);
  ++_version;
  if (_P)
    reassemble_matrix(_P->mat(), *_a_preconditioner, _bcs);
  if (_tied)
    _tied->reduce(_A.mat(), &_A_tied);
  if (_tied and _P)
    _tied->reduce(_P->mat(), &_P_tied);
  _statistics.assembly_time += timer.stop();
  // A linear KSP sees the new matrix state and refactorises by itself; the
  // contact solver lags its preconditioner and must be told.
  if (_contact)
    _contact->operator_changed();
  else
    _linear->operator_changed();
}

long System::newton_steps() const { return _contact ? _contact->newton_iterations() : 0; }

SolverStatistics System::statistics() const
{
  SolverStatistics s = _statistics;
  _stage.read(s);
  // PCSetUp events count factorisations; an AMG hierarchy logs one per
  // level and smoother as well, so the solvers count their own set-ups
  // (their times too: PETSc's event times include the nested set-ups).
  if (_method == Method::iterative and !_contact)
    s.setups = _linear->setups, s.setup_time = _linear->setup_time;
  else if (_method == Method::iterative and _contact->preconditioner_setups() >= 0)
    s.setups = _contact->preconditioner_setups(), s.setup_time = _contact->preconditioner_setup_time();
  if (_contact)
  {
    s.newton_iterations = _contact->newton_iterations();
    s.linear_iterations = _contact->linear_iterations();
    s.active_set_changes = _contact->active_set_changes();
    s.schur_columns = _contact->schur_columns();
    s.schur_factorizations = _contact->schur_factorizations();
    s.contact_factorizations = _contact->contact_factorizations();
    s.schur_time = _contact->schur_time();
  }
  for (const auto& [name, count] : solver_counts)
    s.*count += _earlier.*count;
  return s;
}

std::string System::description() const
{
  const std::string pc = option(_prefix, "-pc_type");
  // With the factorisation reused, the contact's Newton steps run GMRES on
  // it, not the system's own Krylov method.
  const std::string krylov = _contact and _contact->reuses_factorization()
                                 ? "Newton steps by gmres on the last factorisation: "
                                 : option(_prefix, "-ksp_type") + " + ";
  std::string d = (_contact ? "SNES vinewtonrsls (" + _contact->method() + "), " : "") + krylov + pc;
  // PCREDUNDANT: the factorisation each rank holds a copy of.
  const std::string factor = factor_prefix(_prefix);
  const std::string factor_pc = option(factor, "-pc_type");
  if (const std::string package = option(factor, "-pc_factor_mat_solver_type");
      !package.empty() and (factor_pc == "lu" or factor_pc == "cholesky"))
  {
    d += pc == "redundant" ? " (" + factor_pc + ", " + package + " on each rank)" : " (" + package + ")";
    if (package == "mumps" and option(factor, "-mat_mumps_icntl_7") == "0") // contact/factorization_reuse.h
      d += ", analysis by AMD";
  }
  return d;
}

} // namespace biotcontact
