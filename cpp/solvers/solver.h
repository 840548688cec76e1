// How a system is solved: the one place that chooses the factorisation (or,
// when the command line asks for one, the Krylov method) and sets the
// defaults of each; the solver itself is linear_solver.h's LinearSolver.
//
// Every system (flow, mechanics, monolithic) has its own options prefix and
// its own PETSc log stage, from which its set-ups and back-solves are read
// (solver_statistics.h).
#pragma once

#include "assembly/petsc_error.h"
#include "scene/scene.h"
#include "solvers/field_split.h"
#include "solvers/options.h"
#include "solvers/solver_statistics.h"
#include <algorithm>

#include <cstdint>
#include <functional>
#include <mpi.h>
#include <petscksp.h>
#include <petsclog.h>
#include <stdexcept>
#include <array>
#include <string>
#include <vector>

namespace biotcontact
{

/// What the factorisation may assume of a matrix.
enum class Structure
{
  /// Symmetric positive definite (elasticity with Dirichlet rows): Cholesky.
  spd,
  /// Nonsingular with nonzero diagonal blocks of opposite signs after a
  /// symmetric row scaling (RT0 x P0 with S + L > 0, the coupled system with
  /// S > 0): LU without pivoting is stable in any symmetric ordering
  /// (Vanderbei's quasi-definite matrices).
  quasi_definite,
  /// Anything else (a zero diagonal block, S = 0): LU with pivoting.
  general
};

/// @brief A system as its solvers see it: the options prefix that names
/// it ("flow_": options -flow_*, log stage "flow"), what its matrix is, and
/// the fields of a mixed system (field_split.h; empty for one field).
struct SystemLayout
{
  std::string prefix;
  Structure structure;
  std::vector<Field> fields = {};
};

/// How a system is solved.
enum class Method
{
  /// A sparse factorisation, reused while the matrix is unchanged.
  direct,
  /// A Krylov method with a multilevel preconditioner: CG with smoothed
  /// aggregation AMG (rigid-body near-nullspace) for SPD elasticity,
  /// GMRES with a Schur-complement field split and AMG on the Schur
  /// approximation for the mixed flow system, and for the coupled system
  /// FGMRES preconditioned by one fixed-stress sweep (flow, then mechanics)
  /// built from those two.
  iterative
};

/// "direct" or "iterative", as written in the summary.
std::string method_name(Method method);

/// The crossovers of "auto" on one rank: systems with at least this many
/// unknowns are solved iteratively. They follow the measurements on the
/// 2-core machine in docs/performance.md, section "Issue 10: iterative
/// solvers, 3D at a million unknowns, two ranks" (items 5, "Crossovers
/// and auto", and 8, the monolithic Krylov solve) and section "2026-11-25:
/// more ranks (issue 24)" (item "Is `auto` right": the 3D mechanics).
/// - 3D: a factorisation fills in far more (separators of n^(2/3) against
///   n^(1/2)), so the Krylov methods win early: the flow between 3.2e4 and
///   7.6e4 unknowns, the coupled system near 1e4; the mechanics only at
///   3e4, since the Schur complement's dense VI favours the factorisation
///   when many nodes touch (and that crossover moves with the machine's
///   BLAS and memory bandwidth);
/// - 2D: the factorisations stay faster at every size measured (flow and
///   mechanics up to 2.3e6 unknowns in all, the coupled system up to
///   1.4e5): a 2D nested-dissection factor has O(n log n) fill, and a run
///   makes thousands of cheap back-solves from it. The 2D crossovers lie
///   beyond that.
constexpr std::int64_t crossover_2d_mechanics = 4000000, crossover_2d_flow = 8000000;
constexpr std::int64_t crossover_3d_mechanics = 30000, crossover_3d_flow = 50000;
constexpr std::int64_t crossover_2d_monolithic = 8000000, crossover_3d_monolithic = 10000;

/// What "auto" divides a one-rank crossover by on `ranks` ranks: the ranks,
/// since each rank factorises the whole matrix and only the iterative
/// path's time divides; for the 3D mechanics (`mechanics_3d`) the ranks
/// beyond the second: its factorisation with contact stays the faster on
/// two ranks at 1.5e4 and 2.2e4 unknowns (1.4x, OpenBLAS) and loses at
/// 4.5e4 (3x), docs/performance.md, "twenty-fourth session".
constexpr int crossover_divisor(bool mechanics_3d, int ranks)
{
  return std::max(mechanics_3d ? ranks / 2 : ranks, 1);
}

/// The method of a system and why it was chosen (written to the summary).
struct MethodChoice
{
  Method method;
  std::string reason;
};

/// The method for a [solver] choice ("direct", "iterative" or "auto") of a
/// system with `unknowns` global unknowns and `dimension` on `ranks` MPI
/// ranks (`coupled`: the monolithic system). "auto" takes the factorisation
/// below the one-rank crossover divided by the rank count, the Krylov
/// method above it: each rank factorises the whole matrix
/// (set_solver_defaults), so the direct path's time stays that of one
/// rank, while the iterative path's divides by the ranks
/// (docs/performance.md, section "2026-11-25: more ranks (issue 24)",
/// item "What was built" (3)).
MethodChoice choose_method(SolverChoice choice, Structure structure, std::int64_t unknowns, int dimension,
                           int ranks, bool coupled = false);

/// Sets the defaults of the solver with this options prefix unless the
/// command line gave them, and returns the method they make (a
/// -<prefix>pc_type given on the command line decides: a factorisation is
/// direct, anything else iterative; the reason then says so).
///
/// Direct: preonly with the factorisation measured fastest for the
/// structure (docs/performance.md): CHOLMOD Cholesky for SPD matrices and
/// PETSc's own nested-dissection LU for quasi-definite ones, MUMPS for
/// general ones; on several ranks each rank holds a copy of it
/// (PCREDUNDANT, whose options prefix is <prefix>redundant_). A
/// -<prefix>pc_type of lu or cholesky (or a package) on several ranks asks
/// for a factorisation across the ranks (MUMPS unless the package is named).
/// Iterative: see Method; the relative tolerance is set on the KSP
/// (set_relative_tolerance), not here.
/// `fields` are the system's splits: the coupled system is the one whose
/// fields (flow, mechanics) are split further. Throws OptionsError for a
/// -<prefix>ksp_type preonly with an iterative method (no solve then).
MethodChoice set_solver_defaults(const std::string& prefix, Structure structure, MethodChoice method, MPI_Comm comm,
                                 const std::vector<Field>& fields = {});

/// The relative residual tolerance of an iterative solve: tight enough that
/// the coupling tolerance (1e-8 on the relative increments) sees converged
/// solves. Inexact coupling loosens it in early iterations (fixed_stress.h).
constexpr double iterative_tolerance = 1e-10;

/// The value of the PETSc option -<prefix><name without dash> ("" if unset);
/// `name` starts with its dash, e.g. option("flow_", "-pc_type").
std::string option(const std::string& prefix, const char* name);

/// The options prefix of the factorisation of the system with options
/// `prefix`: PCREDUNDANT's inner solver's (prefix + "redundant_") when
/// -<prefix>pc_type is redundant, else `prefix`.
std::string factor_prefix(const std::string& prefix);

/// Sets a PETSc option unless the user already gave it (command line wins).
void set_default_option(const std::string& name, const std::string& value);

/// Whether PETSc's option -name was given by the user (the command line or
/// PETSC_OPTIONS), not set as a default by set_default_option.
bool given_by_user(const std::string& name);

/// The options of `prefix` for a Jacobian that is not symmetric though the
/// system's matrix is (friction's, contact/friction.h): CG becomes GMRES,
/// and a Cholesky factorisation LU by MUMPS (CHOLMOD has no LU), also inside
/// PCREDUNDANT. These override the defaults and the command line alike:
/// neither method solves such a system.
void unsymmetric_jacobian_options(const std::string& prefix);


} // namespace biotcontact
