// One system of a step: the matrix of a bilinear form (Dirichlet rows made
// identity rows) and what answers it, a linear solve A x = b or, with
// contact, the bound-constrained problem on A (contact.h). The flow, the
// mechanics and the monolithic steps each own one; how it is solved, when a
// factorisation is reused and what is counted is decided here and in
// solver.h, never in the steps.
#pragma once

#include "contact/contact.h"
#include "assembly/linear_algebra.h"
#include "assembly/tied_dofs.h"
#include "solvers/linear_solver.h"

#include <dolfinx/fem/Form.h>
#include <dolfinx/fem/Function.h>
#include <memory>
#include <optional>
#include <string>

namespace biotcontact
{

/// @brief Unknowns y appended after a system's own (the conduit faults'
/// pressure, assembly/fault_flow.h), each rank's after its rows of x:
///     [[A + D, E], [B, C]] [x; y] = [b; b_y],   D a diagonal on A's rows,
/// E = B^T (the flow step's symmetric system) unless given (the
/// monolithic step's, where y also loads the displacement's rows and B
/// holds the rate of the faults' opening).
struct AppendedUnknowns
{
  Mat B = nullptr, C = nullptr; // destroyed by the System that holds them
  std::vector<std::pair<PetscInt, double>> diagonal; // (global row of A, value) on the rank that owns the row
  std::vector<double> b;        // b_y (this rank's entries), set before each solve
  std::vector<double> x;        // y: the guess of each solve, then its solution
  Mat E = nullptr;              // A's rows against y; null: B^T (destroyed by the System too)
  /// Added to C's diagonal in the preconditioner's matrix only (this rank's
  /// entries; the iterative path): the fixed-stress term of y's rows.
  std::vector<double> preconditioner_diagonal = {};
};

class System
{
public:
  /// Assembles `a` with `bcs`; `layout` names the system's PETSc options
  /// and its log stage and gives the splits of a mixed system; `choice` is
  /// the scene's [solver] entry ("direct", "iterative" or "auto", see
  /// choose_method); `a_preconditioner` (optional)
  /// the form an iterative method builds its preconditioner from instead
  /// of `a` (the fixed-stress matrix of the coupled system).
  System(MPI_Comm comm, std::shared_ptr<const dolfinx::fem::Form<double>> a, BCs bcs, const SystemLayout& layout,
         SolverChoice choice, std::shared_ptr<const dolfinx::fem::Form<double>> a_preconditioner = nullptr);
  ~System();
  System(const System&) = delete;
  System& operator=(const System&) = delete;

  /// Gives the matrix (and its tied form) its near-nullspace (the rigid-body modes of
  /// elasticity), which algebraic multigrid builds its coarse spaces from.
  void set_near_nullspace(MatNullSpace modes);

  /// Ties unknowns in pairs (x_j = s x_i, tied_dofs.h; the flux across a
  /// transparent fault): every later solve is of the tied system, its
  /// solution x satisfying the ties (collective; nothing when no rank has
  /// a tie).
  void tie(const std::vector<Tie>& ties);

  /// Solves with the AppendedUnknowns from now on (or, called again, with
  /// their new B, C and diagonal: same structure; collective). The System
  /// takes B and C. The appended unknowns join the "pressure" field of an
  /// iterative solve (of the coupled system: its "flow" field and, inside
  /// it, "pressure"), whose preconditioner's matrix is built alike from
  /// the fixed-stress matrix, C plus preconditioner_diagonal.
  void append(AppendedUnknowns appended);
  AppendedUnknowns& appended() { return _appended; }

  /// The vectors [x; y] and [b; b_y] of the system with appended unknowns
  /// (x, b themselves without any), y and b_y the appended ones': what the
  /// contact solver's state and active set read.
  std::pair<Vec, Vec> whole(Vec x, Vec b);

  /// The matrix that is solved: A, A' of the ties, or the system with
  /// appended unknowns.
  Mat operator_matrix() const { return _A_appended ? _A_appended : _A_tied ? _A_tied : _A.mat(); }

  /// The matrix the preconditioner is built from: the operator, or the
  /// matrix of `a_preconditioner` on the iterative path (tied too, and
  /// with appended unknowns).
  Mat preconditioner_matrix() const
  {
    return _P_appended ? _P_appended : _P ? (_P_tied ? _P_tied : _P->mat()) : operator_matrix();
  }

  /// Makes every solve the contact problem of `set` (see ContactSolver:
  /// `displacement_dofs` place V's owned DOFs in x); `layout` is a vector
  /// like x; `balance_rows` the local rows of x's mass balances
  /// (ContactUnknowns). Unknowns appended before are solved with it (their
  /// rows follow x's on each rank: V's DOFs keep their places), their
  /// rows among the mass balances. `once`: the run solves it once
  /// (ContactOperators::once).
  void use_contact(ContactSet set, std::vector<std::int32_t> displacement_dofs, Vec layout,
                   std::vector<std::int32_t> balance_rows = {}, bool once = false);

  /// A time step starts at x: friction's slip increments are measured
  /// from it (ContactSolver::set_slip_reference; nothing without contact).
  void begin_step(Vec x);

  /// The step ending at x was accepted (ContactSolver::accept_step;
  /// nothing without contact).
  void accept_step(Vec x);

  /// Solves with x as the initial guess (a contact solve starts from it).
  void solve(Vec b, Vec x);

  /// The accuracy the coupling asks of the next solves (inexact coupling,
  /// fixed_stress.h): the relative residual tolerance of an iterative
  /// method (and of the contact solver's Newton steps); a factorisation is
  /// exact and ignores it.
  void set_tolerance(double relative);

  /// The form's coefficients changed (dt with time.growth): reassembles A;
  /// the next solve factorises anew.
  void reassemble();

  bool has_contact() const { return _contact != nullptr; }
  ContactSolver& contact() { return *_contact; }

  /// What was done so far (collective only in that every rank reads its log),
  /// counts of an earlier run included (restart).
  SolverStatistics statistics() const;
  /// The contact solver's Newton steps so far in this run (0 without
  /// contact): what statistics() counts, without reading the log.
  long newton_steps() const;
  /// The counts of the run a restart continues.
  void add_earlier(const SolverStatistics& earlier) { _earlier = earlier; }
  /// The solver actually used, e.g. "preonly + cholesky (cholmod)".
  std::string description() const;
  /// Direct or iterative, as decided from the scene and the options.
  Method method() const { return _method; }
  /// Why the method was chosen: the scene's entry, auto's crossover, or a
  /// PETSc option.
  const std::string& method_reason() const { return _method_reason; }
  /// Global number of unknowns.
  std::int64_t unknowns() const;

private:
  /// The block `a` an appended operator was last filled from, and the
  /// operator's version (reassemblies) then.
  struct FilledFrom
  {
    Mat a = nullptr;
    long version = -1;
  };
  /// [[a + D, B^T], [B, C + c]] as one AIJ matrix, a the operator or the
  /// preconditioner's matrix before the appended unknowns (tied, if so),
  /// c `diagonal` (this rank's entries; none if null): its rows on each
  /// rank are a's, then C's (solvers/block_matrix.h). A new matrix, or
  /// `into` (the one made before, of the same structure) refilled, a's
  /// block only if a was reassembled since `filled`, which it updates.
  Mat appended_operator(Mat a, const std::vector<double>* diagonal, Mat into, FilledFrom& filled);
  /// Adds the appended rows to the fields of an iterative solve, whose
  /// rows on each rank move by those appended on the ranks before.
  void append_to_fields(PetscInt rows);
  /// Solves the system with appended unknowns: [b; b_y] in, [x; y] out
  /// (by the contact solver if there is one).
  void solve_appended(Vec b, Vec x);
  /// Copies x then `appended` into `whole`, a vector of the appended
  /// system.
  static void copy_in(Vec x, const std::vector<double>& appended, Vec whole);

  MPI_Comm _comm;
  std::string _prefix;
  std::shared_ptr<const dolfinx::fem::Form<double>> _a, _a_preconditioner;
  BCs _bcs;
  Structure _structure;
  Method _method;
  std::string _method_reason;
  std::vector<Field> _fields;
  SolverStatistics _statistics; // before _A: its assembly time is counted
  dolfinx::la::petsc::Matrix _A;
  std::optional<dolfinx::la::petsc::Matrix> _P;
  std::unique_ptr<TiedDofs> _tied;
  Mat _A_tied = nullptr, _P_tied = nullptr;
  Vec _b_tied = nullptr, _y_tied = nullptr; // b' and y of the ties
  AppendedUnknowns _appended;
  Mat _A_appended = nullptr, _P_appended = nullptr;
  FilledFrom _A_filled, _P_filled; // what _A_appended and _P_appended hold of A (P)
  long _version = 0;                // reassemblies of A and P
  Vec _b_appended = nullptr, _x_appended = nullptr;
  std::unique_ptr<LinearSolver> _linear;
  std::unique_ptr<ContactSolver> _contact;
  SolverStage _stage;
  SolverStatistics _earlier;
};

} // namespace biotcontact
