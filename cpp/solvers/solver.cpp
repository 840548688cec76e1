#include "solvers/solver.h"

#include <algorithm>
#include <functional>
#include <map>
#include <petscpc.h>
#include <set>

namespace biotcontact
{

namespace
{
/// The options set_default_option has set (names without the dash).
std::set<std::string>& project_defaults()
{
  static std::set<std::string> names;
  return names;
}
} // namespace

void set_default_option(const std::string& name, const std::string& value)
{
  // The messages are built only on failure: this runs for every default.
  PetscBool given = PETSC_FALSE;
  if (const PetscErrorCode ierr = PetscOptionsHasName(nullptr, nullptr, ("-" + name).c_str(), &given); ierr != 0)
    check_petsc(ierr, "the default -" + name + " " + value);
  if (given)
    return;
  if (const PetscErrorCode ierr = PetscOptionsSetValue(nullptr, ("-" + name).c_str(), value.c_str()); ierr != 0)
    check_petsc(ierr, "the default -" + name + " " + value);
  project_defaults().insert(name);
}

bool given_by_user(const std::string& name)
{
  PetscBool given = PETSC_FALSE;
  check_petsc(PetscOptionsHasName(nullptr, nullptr, ("-" + name).c_str(), &given), "reading the option -" + name);
  return given and !project_defaults().contains(name);
}

void unsymmetric_jacobian_options(const std::string& prefix)
{
  auto replace = [](const std::string& p, const char* name, const std::string& from, const std::string& to)
  {
    if (option(p, name) == from)
      check_petsc(PetscOptionsSetValue(nullptr, ("-" + p + (name + 1)).c_str(), to.c_str()),
                  "the options of an unsymmetric Jacobian: PetscOptionsSetValue");
  };
  replace(prefix, "-ksp_type", "cg", "gmres");
  for (const std::string& p : {prefix, prefix + "redundant_"})
    if (option(p, "-pc_type") == "cholesky")
    {
      check_petsc(PetscOptionsSetValue(nullptr, ("-" + p + "pc_type").c_str(), "lu"),
                  "the options of an unsymmetric Jacobian: PetscOptionsSetValue");
      replace(p, "-pc_factor_mat_solver_type", "cholmod", "mumps");
    }
}

std::string method_name(Method method) { return method == Method::direct ? "direct" : "iterative"; }

MethodChoice choose_method(SolverChoice choice, Structure structure, std::int64_t unknowns, int dimension, int ranks,
                           bool coupled)
{
  if (choice != SolverChoice::automatic)
    return {choice == SolverChoice::direct ? Method::direct : Method::iterative,
            "solver." + std::string(name_of(choice)) + " in the scene"};
  // "auto": the one-rank crossover of the system and dimension (solver.h
  // says where each was measured) divided by the ranks, the 3D mechanics'
  // by the ranks beyond the second (crossover_divisor).
  const bool elasticity = structure == Structure::spd;
  const std::int64_t one_rank
      = coupled ? (dimension == 3 ? crossover_3d_monolithic : crossover_2d_monolithic)
                : (dimension == 3 ? (elasticity ? crossover_3d_mechanics : crossover_3d_flow)
                                  : (elasticity ? crossover_2d_mechanics : crossover_2d_flow));
  const int divisor = crossover_divisor(dimension == 3 and elasticity and !coupled, ranks);
  const std::int64_t crossover = one_rank / divisor;
  const Method method = unknowns < crossover ? Method::direct : Method::iterative;
  return {method, "auto: " + std::to_string(unknowns) + (method == Method::direct ? " < " : " >= ")
                      + std::to_string(crossover) + " unknowns, the " + std::to_string(dimension) + "D crossover of "
                      + std::to_string(one_rank) + " on one rank divided by " + std::to_string(divisor) + " for "
                      + std::to_string(ranks) + " rank(s)"};
}

std::string option(const std::string& prefix, const char* name)
{
  char value[64] = "";
  // The message is built only on failure: options are read often.
  if (const PetscErrorCode ierr = PetscOptionsGetString(nullptr, prefix.c_str(), name, value, sizeof value, nullptr);
      ierr != 0)
    check_petsc(ierr, "the option -" + prefix + (name + 1));
  return value;
}

std::string factor_prefix(const std::string& prefix)
{
  return option(prefix, "-pc_type") == "redundant" ? prefix + "redundant_" : prefix;
}

namespace
{
/// Whether a -<prefix>pc_type `pc` solves by a factorisation: lu or
/// cholesky, or redundant with one inside (its -<prefix>redundant_pc_type
/// `inner`, lu where not given).
bool is_factorisation(const std::string& pc, const std::string& inner)
{
  const std::string solved = pc == "redundant" ? (inner.empty() ? "lu" : inner) : pc;
  return solved == "lu" or solved == "cholesky";
}

/// The one-rank factorisation of each structure, as measured on the
/// default scene (docs/performance.md): MUMPS's solve phase costs 5-9
/// times a CHOLMOD or PETSc back-solve of the same matrix at 1e4-1e5
/// unknowns, and a run is thousands of back-solves. PETSc's LU does not
/// pivot, so it only takes quasi-definite matrices.
std::string one_rank_package(Structure structure)
{
  return structure == Structure::spd ? "cholmod" : structure == Structure::quasi_definite ? "petsc" : "mumps";
}

void set_direct_defaults(const std::string& prefix, Structure structure, int ranks)
{
  // On several ranks each rank factorises a copy of the whole matrix
  // (PCREDUNDANT) with the one-rank package: a distributed factorisation's
  // back-solve (MUMPS, SuperLU_DIST) costs 3-7 times the one-rank one on 2
  // ranks at 1e5 unknowns (docs/performance.md, "More ranks"), and the
  // back-solves are most of a run; a contact Schur complement then splits
  // its columns between the ranks (schur_complement.h). A system whose
  // factorisation or package the command line names is factorised across
  // the ranks, by that package or MUMPS.
  const std::string given = option(prefix, "-pc_type");
  const bool named = !given.empty() or !option(prefix, "-pc_factor_mat_solver_type").empty();
  const bool redundant = ranks > 1 and (given == "redundant" or !named);
  const std::string factor = redundant ? prefix + "redundant_" : prefix;
  set_default_option(prefix + "ksp_type", "preonly");
  if (redundant)
  {
    set_default_option(prefix + "pc_type", "redundant");
    set_default_option(factor + "ksp_type", "preonly");
  }
  const std::string pc = structure == Structure::spd ? "cholesky" : "lu";
  std::string package = ranks == 1 or redundant ? one_rank_package(structure) : "mumps";
  const std::string given_factor = option(factor, "-pc_type");
  set_default_option(factor + "pc_type", pc);
  if (!given_factor.empty() and given_factor != pc)
    // The user chose the other factorisation: the package must take it.
    package = "mumps";
  set_default_option(factor + "pc_factor_mat_solver_type", package);
  const std::string used = option(factor, "-pc_factor_mat_solver_type");
  // An ordering given to MUMPS replaces its own analysis (far more fill):
  // only PETSc's factorisation gets nested dissection here.
  if (used == "petsc")
    set_default_option(factor + "pc_factor_mat_ordering_type", "nd");
  if (used == MATSOLVERSUPERLU)
    // The Darcy rows (mu_f/k, 1e22 with a conduit's) and the mass balances
    // (1) lie far apart: pivoting by magnitude without equilibration left
    // conduit_transient's flow solve 4e5 times its right-hand side off.
    set_default_option(factor + "mat_superlu_equil", "true");
  if (used == "mumps")
    // More workspace than MUMPS's default: refactorisations of a changed
    // inactive set may need more pivoting room than the analysis planned.
    set_default_option(factor + "mat_mumps_icntl_14", "400");
}

// Elasticity: smoothed aggregation; the matrix carries block size d and
// the rigid-body modes (mechanics_step.cpp, or the displacement field of
// the coupled system), so aggregates are nodes and the coarse spaces hold
// the rigid motions. A new operator of the same pattern (another contact
// active set, inactive_set_preconditioner.h) keeps the prolongators and
// redoes only the Galerkin products.
void set_elasticity_preconditioner(const std::string& prefix)
{
  set_default_option(prefix + "pc_type", "gamg");
  set_default_option(prefix + "pc_gamg_reuse_interpolation", "true");
}

void set_darcy_preconditioner(const std::string& prefix)
{
  // Mixed RT0 x P0: [M B^T; B -C] with M the flux mass, C = (S+L)/dt times
  // the cell mass. Block factorisation with the Schur complement
  // approximated by C + B diag(M)^-1 B^T ("selfp"): for RT0 on simplices a
  // two-point-flux-like cell Laplacian plus a mass term, which suits AMG;
  // M itself is spectrally equivalent to its diagonal (mesh independent).
  // selfp is built from the matrix as stored (the mass balance times -1,
  // forms/biot.py), so it is negative definite; BoomerAMG takes it as it
  // is (measured: 3.7-4.1 GMRES iterations per solve in 2D, 8.2-8.6 in 3D,
  // flat under refinement, bench/scaling.py).
  set_default_option(prefix + "pc_type", "fieldsplit");
  set_default_option(prefix + "pc_fieldsplit_type", "schur");
  set_default_option(prefix + "pc_fieldsplit_schur_fact_type", "full");
  set_default_option(prefix + "pc_fieldsplit_schur_precondition", "selfp");
  set_default_option(prefix + "fieldsplit_flux_ksp_type", "preonly");
  set_default_option(prefix + "fieldsplit_flux_pc_type", "jacobi");
  set_default_option(prefix + "fieldsplit_pressure_ksp_type", "preonly");
  set_default_option(prefix + "fieldsplit_pressure_pc_type", "hypre");
}

// The coupled (u, z, p) system preconditioned by the fixed-stress split
// (White, Castelletto and Tchelepi, 2016): a multiplicative field split,
// flow first and then mechanics, on the preconditioning matrix
// a_monolithic_preconditioner (forms/biot.py), whose pressure block carries
// the stabilisation -(L/dt)(p, th) of the split's flow step. From a zero
// guess one sweep is one fixed-stress iteration: the flow with the
// stabilised storage, then the mechanics loaded by the new pressure
// (PCFIELDSPLIT takes the off-diagonal block from the same matrix, which
// L leaves unchanged). Each block gets one application of the split's own
// preconditioner (AMG on elasticity, the Schur split on the flow), so the
// sweep is cheap and inexact; FGMRES, since a user may make the block
// solves Krylov methods themselves. GMRES on the monolithic system then
// accelerates the fixed-stress iteration: where the split contracts at
// rate gamma per iteration, the Krylov method is not bound to that rate.
void set_fixed_stress_preconditioner(const std::string& prefix, const std::vector<Field>& fields)
{
  set_default_option(prefix + "ksp_type", "fgmres");
  set_default_option(prefix + "pc_type", "fieldsplit");
  set_default_option(prefix + "pc_fieldsplit_type", "multiplicative");
  for (const Field& f : fields)
  {
    const std::string block = prefix + "fieldsplit_" + f.name + "_";
    set_default_option(block + "ksp_type", "preonly");
    if (f.fields.empty())
      set_elasticity_preconditioner(block);
    else
      set_darcy_preconditioner(block);
  }
}

void set_iterative_defaults(const std::string& prefix, Structure structure, const std::vector<Field>& fields)
{
  if (structure == Structure::spd)
  {
    set_default_option(prefix + "ksp_type", "cg");
    set_elasticity_preconditioner(prefix);
  }
  else if (is_coupled(fields))
    set_fixed_stress_preconditioner(prefix, fields);
  else
  {
    set_default_option(prefix + "ksp_type", "gmres");
    set_darcy_preconditioner(prefix);
  }
}
} // namespace

MethodChoice set_solver_defaults(const std::string& prefix, Structure structure, MethodChoice method, MPI_Comm comm,
                                 const std::vector<Field>& fields)
{
  int ranks = 1;
  MPI_Comm_size(comm, &ranks);
  // A -<prefix>pc_type on the command line decides the method.
  bool users_preconditioner = false;
  if (const std::string given = option(prefix, "-pc_type"); !given.empty())
  {
    const std::string inner = given == "redundant" ? option(prefix + "redundant_", "-pc_type") : "";
    users_preconditioner = !is_factorisation(given, inner);
    method = {users_preconditioner ? Method::iterative : Method::direct,
              "-" + prefix + "pc_type " + given + (inner.empty() ? "" : " -" + prefix + "redundant_pc_type " + inner)};
  }
  // preonly applies the preconditioner once and reports success: a solve
  // only by a factorisation, else a wrong x would pass as solved.
  if (method.method == Method::iterative and option(prefix, "-ksp_type") == KSPPREONLY)
    throw OptionsError("-" + prefix + "ksp_type preonly: it applies the preconditioner once, a solve only by a "
                       "factorisation (lu, cholesky, redundant), not by the iterative solver's (" + method.reason
                       + "): its result would pass unchecked");
  // A preconditioner of the user's is tested on the true residual: in the
  // preconditioned norm (GMRES's, left) a poor one stopped with the true
  // residual 1e3 times above the tolerance (conduit_transient with
  // -flow_pc_type jacobi: p wrong by 100 %, exit 0).
  if (users_preconditioner)
    set_default_option(prefix + "ksp_norm_type", "unpreconditioned");
  if (method.method == Method::direct)
    set_direct_defaults(prefix, structure, ranks);
  else
    set_iterative_defaults(prefix, structure, fields);
  return method;
}

} // namespace biotcontact
