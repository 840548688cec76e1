"""How a system is solved (cpp/solvers/solver.h): the one place that chooses between
a factorisation and a preconditioned Krylov method ([solver], "auto" by
size) and sets the defaults of each; the solver itself is linear_solver's
LinearSolver."""
import enum
import re
from dataclasses import dataclass

from mpi4py import MPI
from petsc4py import PETSc

from ..scene.input import SolverChoice, name_of
from .field_split import is_coupled
from .options import OptionsError


class SolverError(Exception):
    """A solver did not converge: the run stops with this message (exit 3)."""


class Structure(enum.Enum):
    """What the factorisation may assume of a matrix (cpp/solvers/solver.h)."""
    spd = 1             # elasticity with Dirichlet rows: Cholesky
    quasi_definite = 2  # RT0 x P0 with S + L > 0: LU without pivoting is stable
    general = 3         # LU with pivoting


@dataclass
class SystemLayout:
    """A system as its solvers see it: the options prefix that names it
    ("flow_": options -flow_*, log stage "flow"), what its matrix is
    (Structure), and the fields of a mixed system (field_split.py; empty for
    one field)."""
    prefix: str
    structure: Structure
    fields: tuple = ()


def reason_name(enum_, reason):
    """PETSc's name of a converged reason, as the C++ prints it (petsc4py
    3.18 knows -11 only by its deprecated name, and KSP's -3 by another)."""
    name = next((k for k in dir(enum_) if not k.startswith("_") and getattr(enum_, k) == reason), str(reason))
    if enum_ is PETSc.KSP.ConvergedReason and name == "DIVERGED_MAX_IT":
        name = "DIVERGED_ITS"  # KSPConvergedReasons[-3] in C
    return name.replace("DIVERGED_PCSETUP_FAILED", "DIVERGED_PC_FAILED")


# The options set_default_option has set (names without the dash).
_PROJECT_DEFAULTS = set()


def set_default_option(name, value):
    """Sets a PETSc option unless the command line gave it."""
    options = PETSc.Options()
    if not options.hasName(name):
        options.setValue(name, value)
        _PROJECT_DEFAULTS.add(name)


def given_by_user(name):
    """Whether PETSc's option -name was given by the user (the command line
    or PETSC_OPTIONS), not set as a default by set_default_option."""
    return PETSc.Options().hasName(name) and name not in _PROJECT_DEFAULTS


def unsymmetric_jacobian_options(prefix):
    """The options of `prefix` for a Jacobian that is not symmetric though
    the system's matrix is (friction's, contact/friction.py): CG becomes
    GMRES, and a Cholesky factorisation LU by MUMPS (CHOLMOD has no LU), also
    inside PCREDUNDANT. These override the defaults and the command line
    alike: neither method solves such a system."""
    options = PETSc.Options()
    if options.getString(prefix + "ksp_type", "") == "cg":
        options.setValue(prefix + "ksp_type", "gmres")
    for p in (prefix, prefix + "redundant_"):
        if options.getString(p + "pc_type", "") == "cholesky":
            options.setValue(p + "pc_type", "lu")
            if options.getString(p + "pc_factor_mat_solver_type", "") == "cholmod":
                options.setValue(p + "pc_factor_mat_solver_type", "mumps")


class Method(enum.Enum):
    """How a system is solved (cpp/solvers/solver.h)."""
    direct = 1     # a sparse factorisation, reused while the matrix is unchanged
    iterative = 2  # CG + GAMG (elasticity), GMRES + Schur field split (flow), FGMRES + a fixed-stress sweep (coupled)


# The one-rank crossovers of "auto" in unknowns, by dimension and system
# (cpp/solvers/solver.h says where each was measured).
CROSSOVER = {(2, "mechanics"): 4000000, (2, "flow"): 8000000, (2, "monolithic"): 8000000,
             (3, "mechanics"): 30000, (3, "flow"): 50000, (3, "monolithic"): 10000}


def choose_method(choice, structure, unknowns, dimension, ranks, coupled=False):
    """(method, reason) for a [solver] choice: "auto" is direct below the
    measured one-rank crossover divided by crossover_divisor (each rank
    factorises the whole matrix and only the iterative path's time divides by
    the ranks, cpp/solvers/solver.h); `coupled`: the monolithic system."""
    if choice != SolverChoice.automatic:
        return (Method.direct if choice == SolverChoice.direct else Method.iterative,
                f"solver.{name_of(choice)} in the scene")
    system = "monolithic" if coupled else ("mechanics" if structure == Structure.spd else "flow")
    one_rank = CROSSOVER[(3 if dimension == 3 else 2, system)]
    divisor = crossover_divisor(dimension == 3 and system == "mechanics", ranks)
    crossover = one_rank // divisor
    method = Method.direct if unknowns < crossover else Method.iterative
    return method, (f"auto: {unknowns} {'<' if method == Method.direct else '>='} {crossover} unknowns, the "
                    f"{dimension}D crossover of {one_rank} on one rank divided by {divisor} for {ranks} rank(s)")


def crossover_divisor(mechanics_3d, ranks):
    """What auto divides a one-rank crossover by: the ranks, or for the 3D
    mechanics the ranks beyond the second (cpp/solvers/solver.h says why)."""
    return max(ranks // 2 if mechanics_3d else ranks, 1)


def agreed_error(error, comm):
    """The error of a call that every rank of the PETSc.Comm `comm` made, as
    every rank sees it: None where all succeeded, else the error of the
    largest code (this rank's, or a PETSc.Error of that code where another
    rank's failed): every rank then takes one path, the fallback or the
    error (cpp/assembly/petsc_error.h, agreed_code; collective)."""
    code = comm.tompi4py().allreduce(error.ierr if error is not None else 0, op=MPI.MAX)
    return None if code == 0 else error if error is not None and error.ierr == code else PETSc.Error(code)


def petsc_error_text(error):
    """PETSc's own words for a PETSc.Error, e.g. "Unable to find requested
    PC type nonsense (PETSc error 86)": the failing call's first message,
    the last line of petsc4py's traceback (cpp/assembly/petsc_error.h)."""
    lines = [line for line in str(error).splitlines()[1:] if line.strip()]
    words = re.sub(r"^\[\d+\] ", "", lines[-1]).rstrip(". ") if lines else ""
    return f"{words} (PETSc error {error.ierr})" if words else f"PETSc error {error.ierr}"


def _is_factorisation(pc, inner):
    """Whether a -<prefix>pc_type `pc` solves by a factorisation: lu or
    cholesky, or redundant with one inside (its -<prefix>redundant_pc_type
    `inner`, lu where not given)."""
    return ((inner or "lu") if pc == "redundant" else pc) in ("lu", "cholesky")


def _one_rank_package(structure):
    """The one-rank factorisation measured fastest for the structure
    (cpp/solvers/solver.cpp): CHOLMOD for SPD, PETSc's LU for quasi-definite,
    MUMPS otherwise."""
    return {Structure.spd: "cholmod", Structure.quasi_definite: "petsc"}.get(structure, "mumps")


def _set_direct_defaults(prefix, structure, ranks):
    """The one-rank factorisation of the structure; on several ranks each
    rank factorises a copy (PCREDUNDANT, options prefix <prefix>redundant_),
    across the ranks (that package or MUMPS) when the command line names
    the factorisation or the package (cpp/solvers/solver.cpp)."""
    options = PETSc.Options()
    given = options.getString(prefix + "pc_type", "")
    named = bool(given) or bool(options.getString(prefix + "pc_factor_mat_solver_type", ""))
    redundant = ranks > 1 and (given == "redundant" or not named)
    factor = prefix + "redundant_" if redundant else prefix
    set_default_option(prefix + "ksp_type", "preonly")
    if redundant:
        set_default_option(prefix + "pc_type", "redundant")
        set_default_option(factor + "ksp_type", "preonly")
    pc = "cholesky" if structure == Structure.spd else "lu"
    package = _one_rank_package(structure) if ranks == 1 or redundant else "mumps"
    given_factor = options.getString(factor + "pc_type", "")
    set_default_option(factor + "pc_type", pc)
    if given_factor and given_factor != pc:
        package = "mumps"  # the user chose the other factorisation
    set_default_option(factor + "pc_factor_mat_solver_type", package)
    used = options.getString(factor + "pc_factor_mat_solver_type")
    if used == "petsc":  # an ordering given to MUMPS would replace its own analysis
        set_default_option(factor + "pc_factor_mat_ordering_type", "nd")
    if used == "superlu":  # rows 1e22 apart: pivoting by magnitude needs them equilibrated
        set_default_option(factor + "mat_superlu_equil", "true")
    if used == "mumps":  # room for refactorisations of changed inactive sets
        set_default_option(factor + "mat_mumps_icntl_14", "400")


def factor_prefix(prefix):
    """The options prefix of the factorisation of the system with options
    `prefix`: PCREDUNDANT's inner solver's (prefix + "redundant_") when
    -<prefix>pc_type is redundant, else `prefix`."""
    return prefix + "redundant_" if PETSc.Options().getString(prefix + "pc_type", "") == "redundant" else prefix


def _set_elasticity_preconditioner(prefix):
    """Smoothed aggregation on nodes with the rigid-body modes; a new operator
    of the same pattern keeps the prolongators (cpp/solvers/solver.cpp)."""
    set_default_option(prefix + "pc_type", "gamg")
    set_default_option(prefix + "pc_gamg_reuse_interpolation", "true")


def _set_darcy_preconditioner(prefix):
    """Schur field split, selfp (C + B diag(M)^-1 B^T) with BoomerAMG on it."""
    for name, value in (("pc_type", "fieldsplit"), ("pc_fieldsplit_type", "schur"),
                        ("pc_fieldsplit_schur_fact_type", "full"), ("pc_fieldsplit_schur_precondition", "selfp"),
                        ("fieldsplit_flux_ksp_type", "preonly"), ("fieldsplit_flux_pc_type", "jacobi"),
                        ("fieldsplit_pressure_ksp_type", "preonly"), ("fieldsplit_pressure_pc_type", "hypre")):
        set_default_option(prefix + name, value)


def _set_fixed_stress_preconditioner(prefix, fields):
    """FGMRES on the coupled system with one fixed-stress sweep as the
    preconditioner: a multiplicative split, flow then mechanics, on the
    stabilised matrix, each block one application of its own preconditioner
    (cpp/solvers/solver.cpp)."""
    set_default_option(prefix + "ksp_type", "fgmres")
    set_default_option(prefix + "pc_type", "fieldsplit")
    set_default_option(prefix + "pc_fieldsplit_type", "multiplicative")
    for f in fields:
        block = prefix + "fieldsplit_" + f.name + "_"
        set_default_option(block + "ksp_type", "preonly")
        if f.fields:
            _set_darcy_preconditioner(block)
        else:
            _set_elasticity_preconditioner(block)


def _set_iterative_defaults(prefix, structure, fields):
    """CG + smoothed aggregation for SPD elasticity; GMRES + Schur split for
    the mixed flow system; the fixed-stress preconditioner for the coupled
    system, the one whose fields are split further."""
    if structure == Structure.spd:
        set_default_option(prefix + "ksp_type", "cg")
        _set_elasticity_preconditioner(prefix)
    elif is_coupled(fields):
        _set_fixed_stress_preconditioner(prefix, fields)
    else:
        set_default_option(prefix + "ksp_type", "gmres")
        _set_darcy_preconditioner(prefix)


# The relative residual tolerance of an iterative solve (cpp/solvers/solver.h);
# inexact coupling loosens it in early iterations (fixed_stress.py).
ITERATIVE_TOLERANCE = 1e-10


def set_solver_defaults(prefix, structure, method, comm, fields=()):
    """Sets the defaults of the solver with this prefix unless the command
    line gave them; returns the (method, reason) they make (a
    -<prefix>pc_type on the command line decides: a factorisation is direct,
    anything else iterative). Raises OptionsError for a -<prefix>ksp_type
    preonly with an iterative method (no solve then)."""
    given_pc = PETSc.Options().getString(prefix + "pc_type", "")
    users_preconditioner = False
    if given_pc:
        inner = PETSc.Options().getString(prefix + "redundant_pc_type", "") if given_pc == "redundant" else ""
        users_preconditioner = not _is_factorisation(given_pc, inner)
        method = (Method.iterative if users_preconditioner else Method.direct,
                  f"-{prefix}pc_type {given_pc}" + (f" -{prefix}redundant_pc_type {inner}" if inner else ""))
    # preonly applies the preconditioner once and reports success: a solve
    # only by a factorisation, else a wrong x would pass as solved.
    if method[0] == Method.iterative and PETSc.Options().getString(prefix + "ksp_type", "") == "preonly":
        raise OptionsError(f"-{prefix}ksp_type preonly: it applies the preconditioner once, a solve only by a "
                           f"factorisation (lu, cholesky, redundant), not by the iterative solver's ({method[1]}): "
                           "its result would pass unchecked")
    # A preconditioner of the user's is tested on the true residual: in the
    # preconditioned norm (GMRES's, left) a poor one stopped with the true
    # residual 1e3 times above the tolerance (conduit_transient with
    # -flow_pc_type jacobi: p wrong by 100 %, exit 0).
    if users_preconditioner:
        set_default_option(prefix + "ksp_norm_type", "unpreconditioned")
    if method[0] == Method.direct:
        _set_direct_defaults(prefix, structure, comm.size)
    else:
        _set_iterative_defaults(prefix, structure, fields)
    return method
